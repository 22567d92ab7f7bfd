#!/usr/bin/env python3
"""ctest ReadmeCommands: every command in README.md's shell blocks runs and must succeed.

  tests/readme_commands.py SOURCE_DIR BUILD_DIR [--list] [--doc PATH] [--fresh-per-block]

The README cannot rot: each ```sh block is read in order, its variables (`b=...`, `v=...`) kept,
comments dropped, and every command run by bash in a scratch folder laid out like the repository
root (scenarios/, bench/, .ci/ and build/release linked to the real ones), so outputs such as
run.sgr or results/ land in the scratch folder and later commands find them, as they would for a
reader who types the tour top to bottom. A new README command is covered the day it is written.

A few commands are made shorter or safer, always by adding options, never by replacing the
command (SHORTENED below says which and why). A command succeeds when it exits 0, or the code
its README comment names ("(exit 1: ...)"). Two are not run here, because they are the test
command's own phases (NOT_RUN). The viewer's commands run under `xvfb-run -a` for a few frames.
--list prints what would run and exits. --doc PATH reads another page's shell blocks instead
(docs/scale-out.md: ctest ScaleOutDocCommands); --fresh-per-block runs each block in a scratch
folder of its own (a page whose blocks are independent examples).
"""
import os
import re
import shlex
import subprocess
import sys
import tempfile
import time

# (pattern on the command, options appended, why)
SHORTENED = [
    (r"simgrass_bench\b", "--benchmark_min_time=0.001",
     "one short repetition per benchmark: this checks that the command works, bench/ times it"),
    (r"\bsimgrass sweep\b|\$b sweep\b",
     "--seconds 0.05 --repeats 1 --scalars fx32,double --k 1,2 --dt 1/60 --lod off",
     "a small grid of the same sweep (the full default grid takes hours)"),
    (r"bench/ab\.py\b", None, "-n 9 becomes -n 3 (its least: three pairs of 300-tick runs)"),
    (r"cmake --install\b", None, "the prefix becomes a scratch folder instead of /opt/simgrass"),
    (r"simgrass-viewer\b|^\$v\b", "--frames 3 --size 320x240 --msaa 0",
     "under xvfb-run, three frames, then the viewer quits"),
]
NOT_RUN = [
    (r"^\.ci/bootstrap\b", "the two commands are the test command itself"),
    (r"^\.ci/perf-gate\b", "the test command runs it as its own phase (.ci/bootstrap test)"),
]
TIMEOUT_S = 600


def shell_blocks(readme):
    """The commands of every ```sh block, in order: (line number, command, expected exit code).

    A command's expected exit code is 0 unless its comment, or a comment-only line right after
    it, says "(exit N" (the README's `diff` of two different runs exits 1, as documented)."""
    commands, inside, first = [], False, False
    for number, line in enumerate(readme.splitlines(), 1):
        if line.strip().startswith("```"):
            inside = line.strip() == "```sh" and not inside
            first = inside
            continue
        if not inside:
            continue
        command = strip_comment(line).strip()
        expected = re.search(r"\(exit (\d+)", line[len(strip_comment(line)):])
        if command:
            commands.append([number, command, int(expected.group(1)) if expected else 0, first])
            first = False
        elif expected and commands:
            commands[-1][2] = int(expected.group(1))
    return commands


def strip_comment(line):
    """The line without a trailing ` # comment` (a # inside quotes stays)."""
    quote = None
    for i, c in enumerate(line):
        if quote:
            if c == quote:
                quote = None
        elif c in "'\"":
            quote = c
        elif c == "#" and (i == 0 or line[i - 1].isspace()):
            return line[:i]
    return line


def plan(command, scratch):
    """(command to run, note) or (None, reason it is not run here)."""
    for pattern, why in NOT_RUN:
        if re.search(pattern, command):
            return None, why
    run, notes = command, []
    for pattern, extra, why in SHORTENED:
        if not re.search(pattern, command):
            continue
        if "sweep" in pattern and re.search(r"--(plan|job|merge)\b", command):
            continue  # a sharded sweep's steps: the plan holds the (already small) settings
        notes.append(why)
        if pattern.startswith(r"bench/ab"):
            run = re.sub(r"-n\s+\d+", "-n 3", run)
        elif pattern.startswith("cmake"):
            run = re.sub(r"--prefix\s+\S+", "--prefix " + shlex.quote(os.path.join(scratch, "prefix")), run)
        elif "viewer" in pattern:
            run = "xvfb-run -a -s '-screen 0 1024x768x24' " + run + " " + extra
        else:
            run = run + " " + extra
    return run, "; ".join(notes)


def main():
    if len(sys.argv) < 3:
        print(__doc__.strip().splitlines()[2].strip(), file=sys.stderr)
        return 2
    source, build = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    args = sys.argv[3:]
    listing = "--list" in args
    fresh = "--fresh-per-block" in args
    doc = args[args.index("--doc") + 1] if "--doc" in args else "README.md"
    with open(os.path.join(source, doc), encoding="utf-8") as f:
        commands = shell_blocks(f.read())
    if not commands:
        print(f"{doc}: no ```sh block found", file=sys.stderr)
        return 1
    with tempfile.TemporaryDirectory(prefix="simgrass-readme-") as tmp:
        root = os.path.join(tmp, "repo")
        os.makedirs(os.path.join(root, "build"))
        for name in ("scenarios", "bench", ".ci", "docs", "README.md"):
            os.symlink(os.path.join(source, name), os.path.join(root, name))
        os.symlink(build, os.path.join(root, "build", "release"))
        # bench/ab.py's example compares ../base/build/release with build/release: the same build.
        os.makedirs(os.path.join(tmp, "base", "build"))
        os.symlink(build, os.path.join(tmp, "base", "build", "release"))
        env = dict(os.environ, TMPDIR=tmp)
        variables, failures, ran = [], 0, 0
        block, base = None, root
        for number, command, expected, first in commands:
            if fresh and first and not listing:  # a block of its own: a new scratch folder, linked like the first
                block = (block or 0) + 1
                root = os.path.join(tmp, f"block{block}")
                os.makedirs(os.path.join(root, "build"))
                for name in ("scenarios", "bench", ".ci", "docs", "README.md"):
                    os.symlink(os.path.join(source, name), os.path.join(root, name))
                os.symlink(build, os.path.join(root, "build", "release"))
            # b=build/release/replay/simgrass, R=$(python3 -c '...'): kept for every later command
            if re.fullmatch(r"[A-Za-z_]\w*=(\S+|\$\(.*\))", command):
                variables.append(command)
                continue
            run, note = plan(command, tmp)
            if run is None:
                print(f"{doc}:{number}: not run here ({note}): {command}")
                continue
            shown = f"{doc}:{number}: {command}" + (f"\n    run as: {run}  ({note})" if run != command else "")
            if listing:
                print(shown)
                continue
            start = time.monotonic()
            script = "set -e\n" + "\n".join(variables) + "\n" + run + "\n"
            try:
                p = subprocess.run(["bash", "-c", script], cwd=root, env=env, stdin=subprocess.DEVNULL,
                                   stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=TIMEOUT_S)
                code, output = p.returncode, p.stdout.decode("utf-8", "replace")
            except subprocess.TimeoutExpired as e:
                code, output = "timeout", (e.stdout or b"").decode("utf-8", "replace")
            ran += 1
            seconds = time.monotonic() - start
            if code == expected:
                print(f"ok   {seconds:6.1f} s  {shown}" + (f"  (exit {code}, as the README says)" if code else ""))
            else:
                failures += 1
                print(f"FAIL {seconds:6.1f} s  {shown}\n    exit {code}, expected {expected}; its output ends:")
                print("\n".join("    | " + l for l in output.rstrip().splitlines()[-15:]))
        if not listing:
            print(f"{ran - failures} of {ran} {doc} commands succeeded")
        return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
