#!/usr/bin/env python3
"""Writes scenarios/hills.png: a 129x129 8-bit grayscale heightmap of smooth hills.

This is how the committed file was made (python3 standard library only):
    python3 scenarios/make_hills_png.py scenarios/hills.png
"""
import math
import struct
import sys
import zlib


def png_gray8(width, height, rows):
    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)
    raw = b"".join(b"\x00" + bytes(r) for r in rows)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def main():
    n = 129
    rows = []
    for z in range(n):
        row = []
        for x in range(n):
            u, v = x / (n - 1), z / (n - 1)
            h = 0.5 + 0.3 * math.sin(2 * math.pi * 1.5 * u) * math.cos(2 * math.pi * v) \
                + 0.2 * math.exp(-((u - 0.65) ** 2 + (v - 0.4) ** 2) / 0.02)
            row.append(max(0, min(255, int(round(255 * h * 0.8)))))
        rows.append(row)
    with open(sys.argv[1], "wb") as f:
        f.write(png_gray8(n, n, rows))


if __name__ == "__main__":
    main()
