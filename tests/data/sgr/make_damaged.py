#!/usr/bin/env python3
"""Writes the damaged-recording corpus tests/data/sgr/damaged/ (and its EXPECTED.json) from the
small valid recording tests/data/sgr/tiny.sgr.

How the committed files were made (python3 standard library only; the XXH3-64 chunk checksums
come from the system's libxxhash through ctypes, the library the reader itself uses):

    python3 tests/data/sgr/make_damaged.py --record build/release/replay/simgrass

--record SIMGRASS first re-records tiny.sgr from tiny.json (24 ticks, a hash every tick, a
snapshot every 8) and the fuzz seeds in tests/fuzz/corpus/sgr_reader/ with that executable; without it the
corpus is rebuilt from the committed tiny.sgr (the output is then byte-for-byte the same):

    python3 tests/data/sgr/make_damaged.py

Re-record when the physics, the scenario format or the .sgr format changes (tests/
recording_robustness_test.cpp replays the truncated files and expects their hashes to match).

EXPECTED.json maps every file to what reading it must give:
  "truncated": it reads (Recording::truncated), everything in it replays and verifies;
               "truncatedAt" is the offset the reader reports, "message" a substring of what
               it expected there.
  "error":     sgr::RecordingError from parseRecording, snapshotState, recordedScenario, the
               Player or Player::verify; "offset" is the byte offset it names, "message" a
               substring of it.
"kind" groups files by the damage done (the command-line test replays one file per kind).
"""
import argparse
import ctypes
import ctypes.util
import json
import os
import shutil
import struct
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", "..", ".."))
DAMAGED = os.path.join(HERE, "damaged")
SEEDS = os.path.join(REPO, "tests", "fuzz", "corpus", "sgr_reader")

MAGIC = b"\x89SGR\r\n\x1a\n"
VERSION = 2
PREAMBLE = 12
MAX_PAYLOAD = {b"HEAD": 256 << 20, b"INPT": 1 << 20, b"CHCK": 16, b"SNAP": 1 << 31, b"END ": 8 + 8 + 1 + 4 + 4096}
NAME = {b"HEAD": "HEAD", b"INPT": "INPT", b"CHCK": "CHCK", b"SNAP": "SNAP", b"END ": "END"}


def _xxh3():
    name = ctypes.util.find_library("xxhash") or "libxxhash.so.0"
    try:
        lib = ctypes.CDLL(name)
    except OSError as e:
        sys.exit(f"make_damaged.py: cannot load libxxhash ({e}); install libxxhash-dev (or libxxhash0)")
    fn = lib.XXH3_64bits
    fn.restype = ctypes.c_uint64
    fn.argtypes = [ctypes.c_char_p, ctypes.c_size_t]
    return lambda data: fn(bytes(data), len(data))


xxh3 = _xxh3()


# ---- chunks ------------------------------------------------------------------------------------
def frame(kind, payload):
    """type | length | payload | XXH3-64 of the three (as sgr::frameChunk)."""
    body = kind + struct.pack("<I", len(payload)) + payload
    return body + struct.pack("<Q", xxh3(body))


def chunks(data):
    """(offset, type, payload length) of every complete chunk of a valid recording."""
    out, at = [], PREAMBLE
    while at + 8 <= len(data):
        kind, length = data[at:at + 4], struct.unpack_from("<I", data, at + 4)[0]
        out.append((at, kind, length))
        at += 16 + length
    return out


def payload(data, chunk):
    at, _, length = chunk
    return data[at + 8:at + 8 + length]


def replace_chunk(data, chunk, new_bytes):
    at, _, length = chunk
    return data[:at] + new_bytes + data[at + 16 + length:]


def head_fields(p):
    """Offsets inside a HEAD payload: the scenario hash and the (length-prefixed) strings."""
    at = 36  # scalar, reserved, reserved, checkEvery, snapshotEvery, scenarioHash, initialHash, startTick
    strings = {}
    for name in ("variant", "source", "text"):
        n = struct.unpack_from("<I", p, at)[0]
        strings[name] = (at, n)
        at += 4 + n
    return strings


def with_scenario_text(p, text, fix_hash=True):
    """A HEAD payload with another scenario text (and its hash, unless fix_hash is False)."""
    at, n = head_fields(p)["text"]
    out = p[:at] + struct.pack("<I", len(text)) + text + p[at + 4 + n:]
    if fix_hash:
        out = out[:12] + struct.pack("<Q", xxh3(text)) + out[20:]
    return out


# ---- what the reader makes of a file (chunk level; payloads are assumed as recorded) -----------
def predict(data):
    """The outcome sgr::parseRecording gives for damage to the framing (magic, version, types,
    lengths, checksums, order, cuts). Payload contents are taken to be the recorded ones."""
    def error(offset, message):
        return {"outcome": "error", "offset": offset, "message": message}

    if len(data) < PREAMBLE or data[:8] != MAGIC:
        if len(data) >= 8 and data[:8] != MAGIC:
            return error(0, "the .sgr magic")
        return error(len(data), "the 12-byte .sgr preamble (the file ends early)")
    version = struct.unpack_from("<I", data, 8)[0]
    if version == 1:  # the same layout, the hashes of another definition
        return error(8, f"format version {VERSION}, got 1 (recorded before 2026-11-28")
    if version != VERSION:
        return error(8, f"format version {VERSION}, got {version}")
    at, have_head, ended, cut = PREAMBLE, False, False, None
    while at < len(data):
        if ended:
            return error(at, "the end of the file after the END chunk")
        if len(data) - at < 8:
            cut = (at, "an 8-byte chunk header")
            break
        kind, length = data[at:at + 4], struct.unpack_from("<I", data, at + 4)[0]
        if kind not in MAX_PAYLOAD:
            return error(at, "a chunk type HEAD, INPT, CHCK, SNAP or END, got")
        if length > MAX_PAYLOAD[kind]:
            return error(at + 4, f"a {NAME[kind]} payload of at most {MAX_PAYLOAD[kind]} bytes, got {length}")
        total = 16 + length
        if len(data) - at < total:
            cut = (at, f"a {NAME[kind]} chunk of {total} bytes, {len(data) - at} left")
            break
        stored = struct.unpack_from("<Q", data, at + 8 + length)[0]
        if xxh3(data[at:at + 8 + length]) != stored:
            return error(at + 8 + length, f"the {NAME[kind]} chunk's checksum (the chunk at byte {at} is damaged)")
        if not have_head and kind != b"HEAD":
            return error(at, "the HEAD chunk first")
        if have_head and kind == b"HEAD":
            return error(at, "one HEAD chunk only")
        have_head = have_head or kind == b"HEAD"
        ended = ended or kind == b"END "
        at += total
    if not have_head:
        return error(at, "the HEAD chunk (the file ends early)")
    if cut is None and not ended:
        cut = (at, "the END chunk (the recording was not finished)")
    if cut is not None:
        return {"outcome": "truncated", "truncatedAt": cut[0], "message": cut[1]}
    return {"outcome": "ok"}


# ---- the corpus --------------------------------------------------------------------------------
def cut_points(data):
    """Every cut in the preamble and the first 64 bytes of HEAD, every chunk boundary +-1, every
    7th byte (every cut of the 3.7 KB tiny.sgr would be 6.8 MB)."""
    points = set(range(0, PREAMBLE + 64 + 1))
    for at, _, length in chunks(data):
        for b in (at, at + 16 + length):
            points.update((b - 1, b, b + 1))
    points.update(range(0, len(data), 7))
    return sorted(p for p in points if 0 <= p < len(data))


def flip(data, offset, bit):
    out = bytearray(data)
    out[offset] ^= 1 << bit
    return bytes(out)


def build(data):
    """{file name: (bytes, expectation)}; expectation None means: predict() it."""
    files = {}

    def add(name, kind, blob, expect=None):
        assert name not in files, name
        e = dict(expect) if expect else predict(blob)
        if expect:  # damage behind valid checksums: the framing must still read
            assert predict(blob) == {"outcome": "ok"}, f"{name}: {predict(blob)}"
        assert e["outcome"] != "ok", f"{name} reads as an undamaged recording"
        e["kind"] = kind
        files[name] = (blob, e)

    cs = chunks(data)
    assert predict(data) == {"outcome": "ok"}, "the source recording is not a complete, valid one"
    head_end = cs[0][0] + 16 + cs[0][2]
    first = {}
    for c in cs:
        first.setdefault(c[1], c)
    assert set(first) == set(MAX_PAYLOAD), f"the source recording lacks chunk types: {set(MAX_PAYLOAD) - set(first)}"

    # Every cut (the recorder killed mid-write, a partial download).
    for n in cut_points(data):
        kind = "cut-preamble" if n < PREAMBLE else "cut-head" if n < head_end else "cut"
        add(f"trunc-{n:05d}.sgr", kind, data[:n])

    # Bit flips in each chunk type: the type, the length (a small and a large change), the payload
    # and the checksum. The first chunk of each type (END: the only one).
    for kind, (at, _, length) in first.items():
        t = NAME[kind]
        add(f"flip-{t}-type.sgr", "flip-type", flip(data, at, 0))
        add(f"flip-{t}-length-bit01.sgr", "flip-length", flip(data, at + 4, 1))
        add(f"flip-{t}-length-bit24.sgr", "flip-length", flip(data, at + 7, 0))
        add(f"flip-{t}-payload.sgr", "flip-payload", flip(data, at + 8 + length // 2, 5))
        add(f"flip-{t}-checksum.sgr", "flip-checksum", flip(data, at + 8 + length + 3, 7))
    add("flip-CHCK-last-payload-2bits.sgr", "flip-payload",
        flip(flip(data, cs[-2][0] + 8, 0), cs[-2][0] + 8 + 9, 6))

    # Not a recording of this format.
    add("magic-wrong.sgr", "magic", flip(data, 2, 5))  # "\x89SgR..."
    add("magic-png.sgr", "magic", b"\x89PNG\r\n\x1a\n" + data[8:])
    add("magic-short.sgr", "magic", b"SGR" + data[3:12])
    add("version-1.sgr", "version", data[:8] + struct.pack("<I", 1) + data[12:])
    add("version-3.sgr", "version", data[:8] + struct.pack("<I", 3) + data[12:])
    add("version-0.sgr", "version", data[:8] + struct.pack("<I", 0) + data[12:])

    # Chunk order and extra chunks, all with valid checksums.
    xtra = frame(b"XTRA", b"\x00\x01\x02\x03")
    add("unknown-type-valid-checksum.sgr", "unknown-type", data[:head_end] + xtra + data[head_end:])
    add("unknown-type-lowercase-head.sgr", "unknown-type",
        data[:PREAMBLE] + frame(b"head", payload(data, cs[0])) + data[head_end:])
    add("order-no-head.sgr", "order", data[:PREAMBLE] + data[head_end:])
    add("order-two-heads.sgr", "order", data[:head_end] + data[PREAMBLE:])
    add("order-after-end.sgr", "order", data + frame(b"CHCK", struct.pack("<qQ", 1000, 0)))
    chk = [c for c in cs if c[1] == b"CHCK"]
    a, b = chk[0], chk[1]
    swapped = data[:a[0]] + data[b[0]:b[0] + 32] + data[a[0]:a[0] + 32] + data[b[0] + 32:]
    add("order-checks-swapped.sgr", "order", swapped,
        {"outcome": "error", "offset": a[0] + 8, "message": "the check of tick 1, got tick 2"})
    add("order-check-missing.sgr", "order", data[:a[0]] + data[a[0] + 32:],
        {"outcome": "error", "offset": a[0] + 8, "message": "the check of tick 1, got tick 2"})
    end = first[b"END "]
    ep = payload(data, end)
    add("end-tick-forged.sgr", "end-field",
        replace_chunk(data, end, frame(b"END ", struct.pack("<q", 10 ** 12) + ep[8:])),
        {"outcome": "error", "offset": end[0] + 8, "message": "a final tick from"})

    # Absurd lengths (the reader must not allocate or seek by them).
    for kind, value in ((b"SNAP", 0xFFFFFFF0), (b"HEAD", 0xFFFFFFFF), (b"INPT", 0x7FFFFFFF)):
        at = first[kind][0]
        add(f"length-absurd-{NAME[kind]}.sgr", "absurd-length",
            data[:at + 4] + struct.pack("<I", value) + data[at + 8:])

    # Damaged contents behind a valid checksum: only the field checks can catch these.
    snap = first[b"SNAP"]
    sp = payload(data, snap)
    frame_at = snap[0] + 8 + 24
    raw_size = struct.unpack_from("<Q", sp, 16)[0]
    add("snap-zstd-magic.sgr", "zstd", replace_chunk(data, snap, frame(b"SNAP", sp[:24] + b"\x00" + sp[25:])),
        {"outcome": "error", "offset": frame_at, "message": f"a zstd frame of {raw_size} bytes"})
    add("snap-zstd-cut.sgr", "zstd", replace_chunk(data, snap, frame(b"SNAP", sp[:-12])),
        {"outcome": "error", "offset": frame_at, "message": "a valid zstd frame"})
    add("snap-raw-size.sgr", "zstd",
        replace_chunk(data, snap, frame(b"SNAP", sp[:16] + struct.pack("<Q", raw_size + 8) + sp[24:])),
        {"outcome": "error", "offset": frame_at, "message": f"a zstd frame of {raw_size + 8} bytes"})
    # A 17-byte zstd frame that declares 4 GiB of content (one RLE block): the size must be refused
    # before anything is allocated for it.
    bomb = (b"\x28\xb5\x2f\xfd" + b"\xe0" + struct.pack("<Q", 1 << 32)
            + (1 | 1 << 1 | (128 << 10) << 3).to_bytes(3, "little") + b"\x00")
    add("snap-raw-size-bomb.sgr", "snap-field",
        replace_chunk(data, snap, frame(b"SNAP", sp[:16] + struct.pack("<Q", 1 << 32) + bomb)),
        {"outcome": "error", "offset": snap[0] + 8 + 16, "message": "17 compressed bytes can hold"})
    add("snap-raw-size-zero.sgr", "snap-field",
        replace_chunk(data, snap, frame(b"SNAP", sp[:16] + struct.pack("<Q", 0) + sp[24:])),
        {"outcome": "error", "offset": snap[0] + 8 + 16, "message": "a snapshot size between 1 and"})

    inpt = first[b"INPT"]
    ip = payload(data, inpt)
    assert ip[8] == 0 and struct.unpack_from("<I", ip, 9)[0] >= 1, "the first INPT should carry a command"
    body_at = 13
    # Body indices up to 63 may name spawned bodies (kMaxBodies = 64): 70 can never exist.
    add("inpt-body-out-of-range.sgr", "body-index",
        replace_chunk(data, inpt, frame(b"INPT", ip[:body_at] + struct.pack("<i", 70) + ip[body_at + 4:])),
        {"outcome": "error", "offset": inpt[0] + 8, "message": "commands for at most 64 bodies, got body 70"})
    add("inpt-body-negative.sgr", "inpt-field",
        replace_chunk(data, inpt, frame(b"INPT", ip[:body_at] + struct.pack("<i", -1) + ip[body_at + 4:])),
        {"outcome": "error", "offset": inpt[0] + 8 + body_at, "message": "a body index >= 0, got -1"})
    add("inpt-command-kind.sgr", "inpt-field",
        replace_chunk(data, inpt, frame(b"INPT", ip[:body_at + 4] + b"\x09" + ip[body_at + 5:])),
        {"outcome": "error", "offset": inpt[0] + 8 + body_at + 4, "message": "a command kind 0..8, got 9"})
    add("inpt-command-count.sgr", "inpt-field",
        replace_chunk(data, inpt, frame(b"INPT", ip[:9] + struct.pack("<I", 0x10000000) + ip[13:])),
        {"outcome": "error", "offset": inpt[0] + 8 + 9, "message": "a command count that fits the INPT chunk"})

    # Ticks at the end of the int64 range (the reader's arithmetic on them must not overflow): an
    # input for the last representable tick, and a faulted END there in a recording without checks.
    int64_max = (1 << 63) - 1
    last_inpt = [c for c in cs if c[1] == b"INPT"][-1]
    forged = replace_chunk(data, last_inpt,
                           frame(b"INPT", struct.pack("<q", int64_max) + payload(data, last_inpt)[8:]))
    add("inpt-tick-max.sgr", "end-field", forged,
        {"outcome": "error", "offset": last_inpt[0] + 8, "message": f"an input tick at most {1 << 16} ticks after"})
    no_hashes = bytearray(payload(data, cs[0]))
    no_hashes[4:12] = struct.pack("<II", 0, 0)  # checkEvery, snapshotEvery
    kept = [c for c in cs[1:] if c[1] in (b"INPT", b"END ")]
    faulted = frame(b"END ", struct.pack("<qQB", int64_max, 0, 1) + struct.pack("<I", 5) + b"fault")
    blob = data[:PREAMBLE] + frame(b"HEAD", bytes(no_hashes)) + b"".join(
        data[c[0]:c[0] + 16 + c[2]] for c in kept if c[1] == b"INPT") + faulted
    add("end-faulted-tick-max.sgr", "end-field", blob,
        {"outcome": "error", "offset": len(blob) - len(faulted) + 8, "message": "a final tick from"})

    # Chunks the header promises, missing (valid checksums): every SNAP removed, every CHCK removed.
    no_snaps = data[:PREAMBLE] + b"".join(data[c[0]:c[0] + 16 + c[2]] for c in cs if c[1] != b"SNAP")
    first_check = [c for c in cs if c[1] == b"CHCK"]
    snap_tick = struct.unpack_from("<q", payload(data, first[b"SNAP"]), 0)[0]
    check_at = next(c for c in first_check if struct.unpack_from("<q", payload(data, c), 0)[0] == snap_tick)
    removed_before = sum(16 + c[2] for c in cs if c[1] == b"SNAP" and c[0] < check_at[0])
    add("missing-snapshots.sgr", "missing-chunk", no_snaps,
        {"outcome": "error", "offset": check_at[0] - removed_before + 8,
         "message": f"the SNAP chunk of tick {snap_tick} before the check of tick {snap_tick}"})
    no_checks = data[:PREAMBLE] + b"".join(data[c[0]:c[0] + 16 + c[2]] for c in cs if c[1] != b"CHCK")
    first_input_after = next(c for c in cs if c[1] == b"INPT" and struct.unpack_from("<q", payload(data, c), 0)[0] >= 1)
    removed_before = sum(16 + c[2] for c in cs if c[1] == b"CHCK" and c[0] < first_input_after[0])
    add("missing-checks.sgr", "missing-chunk", no_checks,
        {"outcome": "error", "offset": first_input_after[0] - removed_before + 8,
         "message": "the CHCK chunk of tick 1 before the input of tick"})

    # Ticks no replay could reach in reasonable time (hashes off, so no interval bounds them).
    gap = 1 << 16
    unbounded_end = frame(b"END ", struct.pack("<qQB", 1 << 40, 0, 0) + struct.pack("<I", 0))
    blob = data[:PREAMBLE] + frame(b"HEAD", bytes(no_hashes)) + b"".join(
        data[c[0]:c[0] + 16 + c[2]] for c in kept if c[1] == b"INPT") + unbounded_end
    add("end-tick-unbounded.sgr", "tick-span", blob,
        {"outcome": "error", "offset": len(blob) - len(unbounded_end) + 8,
         "message": f"(at most {gap} ticks after the last tick the file names)"})
    far_start = bytearray(payload(data, cs[0]))
    far_start[28:36] = struct.pack("<q", 1 << 40)
    add("start-tick-far.sgr", "tick-span", replace_chunk(data, cs[0], frame(b"HEAD", bytes(far_start))),
        {"outcome": "error", "offset": PREAMBLE + 8 + 28, "message": f"a start tick from 0 to {gap}"})

    hp = payload(data, cs[0])
    text_at, _ = head_fields(hp)["text"]
    add("head-scenario-invalid-json.sgr", "scenario",
        replace_chunk(data, cs[0], frame(b"HEAD", with_scenario_text(hp, b'{"name": "sgr-tiny", "field": {'))),
        {"outcome": "error", "offset": PREAMBLE, "message": "a scenario that loads"})
    add("head-scenario-hash.sgr", "head-field",
        replace_chunk(data, cs[0], frame(b"HEAD", with_scenario_text(hp, b"{}", fix_hash=False))),
        {"outcome": "error", "offset": PREAMBLE + 8 + text_at, "message": "scenario text matching its hash"})
    add("head-scalar.sgr", "head-field", replace_chunk(data, cs[0], frame(b"HEAD", b"\x07" + hp[1:])),
        {"outcome": "error", "offset": PREAMBLE + 8, "message": "a scalar type 0..3, got 7"})
    add("head-scalar-variant.sgr", "scenario", replace_chunk(data, cs[0], frame(b"HEAD", b"\x01" + hp[1:])),
        {"outcome": "error", "offset": PREAMBLE + 8, "message": "the header's scalar type to match its variant"})
    return files


def expected_json(files):
    lines = ["{", '  "source": "tiny.sgr",', '  "generator": "make_damaged.py",', '  "files": {']
    names = sorted(files)
    for i, name in enumerate(names):
        e = files[name][1]
        order = ["kind", "outcome", "offset", "truncatedAt", "message"]
        entry = json.dumps({k: e[k] for k in order if k in e}, ensure_ascii=True)
        lines.append(f"    {json.dumps(name)}: {entry}{',' if i + 1 < len(names) else ''}")
    lines += ["  }", "}", ""]
    return "\n".join(lines)


def write_corpus(source):
    with open(source, "rb") as f:
        data = f.read()
    files = build(data)
    if os.path.isdir(DAMAGED):
        for old in os.listdir(DAMAGED):
            os.remove(os.path.join(DAMAGED, old))
    os.makedirs(DAMAGED, exist_ok=True)
    total = 0
    for name, (blob, _) in files.items():
        with open(os.path.join(DAMAGED, name), "wb") as f:
            f.write(blob)
        total += len(blob)
    with open(os.path.join(DAMAGED, "EXPECTED.json"), "w") as f:
        f.write(expected_json(files))
    print(f"{len(files)} damaged files, {total / 1e6:.2f} MB, in {os.path.relpath(DAMAGED, REPO)}")


# ---- recording the sources ---------------------------------------------------------------------
def record(simgrass, cwd, args):
    cmd = [simgrass, "record"] + args
    r = subprocess.run(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        sys.exit(f"make_damaged.py: {' '.join(cmd)} failed ({r.returncode}):\n{r.stderr}")


def record_sources(simgrass):
    simgrass = os.path.abspath(simgrass)
    record(simgrass, HERE, ["tiny.json", "-o", "tiny.sgr", "--ticks", "24", "--snapshot-every", "8"])
    os.makedirs(SEEDS, exist_ok=True)
    with open(os.path.join(HERE, "tiny.sgr"), "rb") as f:
        tiny = f.read()
    shutil.copyfile(os.path.join(HERE, "tiny.sgr"), os.path.join(SEEDS, "tiny-fx32.sgr"))
    snap = [c for c in chunks(tiny) if c[1] == b"SNAP"][1]
    with open(os.path.join(SEEDS, "tiny-cut-in-snap.sgr"), "wb") as f:
        f.write(tiny[:snap[0] + 100])
    record(simgrass, HERE, ["tiny.json", "-o", os.path.join(SEEDS, "tiny-double-nochecks.sgr"), "--ticks", "6",
                            "--check-every", "0", "--snapshot-every", "0", "--variant", "scalar=double"])
    # A heightmap embedded in the HEAD (4 x 4 samples), fx16, interpolation 2.
    sys.dont_write_bytecode = True  # no scenarios/__pycache__
    sys.path.insert(0, os.path.join(REPO, "scenarios"))
    from make_hills_png import png_gray8  # pylint: disable=import-outside-toplevel
    with open(os.path.join(HERE, "tiny.json"), "rb") as f:
        scenario = json.load(f)
    scenario["name"] = "sgr-tiny-hills"
    scenario["terrain"] = {"type": "heightmap", "file": "bump.png", "cellSize": 0.5, "maxHeight": 1}
    with tempfile.TemporaryDirectory() as tmp:
        with open(os.path.join(tmp, "hills.json"), "w") as f:
            json.dump(scenario, f, separators=(",", ":"))
        with open(os.path.join(tmp, "bump.png"), "wb") as f:
            f.write(png_gray8(4, 4, [[0, 40, 80, 40], [40, 120, 160, 80], [40, 80, 120, 40], [0, 40, 40, 0]]))
        record(simgrass, tmp, ["hills.json", "-o", os.path.join(SEEDS, "tiny-hills-fx16.sgr"), "--ticks", "10",
                               "--check-every", "3", "--snapshot-every", "5", "--variant", "scalar=fx16",
                               "--variant", "interp=2"])
    print(f"recorded {os.path.relpath(os.path.join(HERE, 'tiny.sgr'), REPO)} and the seeds in "
          f"{os.path.relpath(SEEDS, REPO)}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--record", metavar="SIMGRASS", help="re-record tiny.sgr and the fuzz seeds with this executable")
    args = ap.parse_args()
    if args.record:
        record_sources(args.record)
    write_corpus(os.path.join(HERE, "tiny.sgr"))


if __name__ == "__main__":
    main()
