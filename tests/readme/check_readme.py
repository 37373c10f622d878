#!/usr/bin/python3
"""The README's output blocks are what the commands print now (issue 13).

    python3 check_readme.py README.md BUILD_DIR SHARED_DATA_DIR [--only LINE]
        [--commands REGEX [--as-test] | --other-than REGEX]

--only LINE checks the one block whose first line is LINE; --commands REGEX
checks only the blocks whose command starts with a match of REGEX (and fails
when there is none: a block removed from the README), --other-than
REGEX all the others.  CMake registers one test per benchmark this way and
one for the rest, so ctest runs them side by side.

--as-test (with --commands) makes the check a test program's own ctest test:
a test program, notebook or test script whose output the README shows runs
once, not once as a test and again for the README.  The command then runs
even without the shared data (only the comparison of a skip-without-shared
block is skipped, its exit code still counts), and a command that exits 77
(the program skipped itself) makes the check exit 77, ctest's skip.

Every fenced block without a language tag must be preceded (blank lines
allowed) by one of two HTML comments, invisible on a rendered page:

    <!-- output: COMMAND [| option ...] -->    the block is COMMAND's output
    <!-- not output: why -->                    a file format, a schema, a layout

COMMAND runs with /bin/sh in a scratch folder laid out like a checkout
(build/, measurements/, tests/, notebooks_c/, scripts/ link to the real ones;
../shared/ to the shared data), so the README's own paths work and nothing is
written into the checkout.  Its stdout is compared with the block:
  - a block line starting with "$ " is the command as shown to the reader
    and is skipped;
  - a line that is just "..." stands for any number of lines (an excerpt);
  - "..." inside a line stands for any text within that line;
  - trailing blanks are ignored.
Options:
  stderr        compare stdout and stderr together (2>&1)
  exit=N        the exit code expected (default 0)
  timings       a benchmark's "key: value" lines (every command runs with
                PHC_BENCH_QUICK=1: a benchmark times once where it would
                take the best of several): values that are times,
                rates, ratios of times or verdicts drawn from them are one
                machine's measurements (the text before the block says which
                and when) and are not compared; the keys, their order and
                every other value (a model's number, a checksum) are
  skip-without-shared   skip (with a message) when the shared data is absent

Prints "ok - ..." / "not ok - ..." per block with a diff, then
"N passed, M failed, K skipped"; exits 1 when any block differs.
"""
import difflib
import os
import resource
import re
import shutil
import subprocess
import sys
import tempfile
import time

MARK = re.compile(r"^<!--\s*(output|not output):\s*(.*?)\s*-->\s*$")


def parse(readme):
    """Yields (line_no, fence_lang, body_lines, marker) for each fenced block."""
    lines = open(readme, encoding="utf-8").read().split("\n")
    i = 0
    while i < len(lines):
        line = lines[i]
        if line.startswith("```"):
            lang = line[3:].strip()
            start = i
            body = []
            i += 1
            while i < len(lines) and not lines[i].startswith("```"):
                body.append(lines[i])
                i += 1
            marker = None
            j = start - 1
            while j >= 0 and lines[j].strip() == "":
                j -= 1
            if j >= 0:
                m = MARK.match(lines[j])
                if m:
                    marker = (m.group(1), m.group(2))
            yield start + 1, lang, body, marker
        i += 1


# In a benchmark's "key: value" line, the value is one machine's measurement
# when the key or the value's unit says it is a time, a rate, a ratio of
# times, a memory size or a verdict drawn from them; other values (a model's
# number, a checksum, a count) are compared like any output.
MEASURED_KEY = re.compile(r"time|_ns|ns_|_ms|ms_|_us|vups|_bw|bw_|speed|ratio|memory|load|overhead|per_s|"
                          r"s_per|target|linear|quiet|mpix|fraction|cost|threads|version|timed|lre")
MEASURED_UNIT = re.compile(r"\d\s*(s|ms|us|ns|x|B|GB/s|voxel/s|digits|CPUs)(?=$|[\s,;()])")


def mask_timing(line):
    key, colon, value = line.partition(":")
    if colon and (MEASURED_KEY.search(key) or MEASURED_UNIT.search(value)):
        return key + ": <measured>"
    return line


def line_matches(want, got):
    if "..." not in want:
        return want == got
    parts = [re.escape(p) for p in want.split("...")]
    return re.fullmatch(".*".join(parts), got) is not None


def block_matches(want, got):
    """Matches block lines against output lines; "..." lines match any run."""
    memo = {}

    def match(i, j):
        key = (i, j)
        if key in memo:
            return memo[key]
        if i == len(want):
            r = j == len(got)
        elif want[i] == "...":
            r = any(match(i + 1, k) for k in range(j, len(got) + 1))
        else:
            r = j < len(got) and line_matches(want[i], got[j]) and match(i + 1, j + 1)
        memo[key] = r
        return r

    return match(0, 0)


# A unit or real-data test program run without arguments writes no files, so
# two blocks showing its output share one run (two README sections quote
# the particle and shape-series tests).
READ_ONLY_TEST = re.compile(r"^build/(unit_test|realdata_test)_[A-Za-z0-9_]+$")


# Benchmarks repeat a timing once instead of taking the best or median of
# several (tests/bench/bench_machine.h, bench_repeats): their keys and model
# values do not depend on the repeats and their measured values are masked.
QUICK_ENV = dict(os.environ, PHC_BENCH_QUICK="1")


def children_cpu():
    """CPU seconds (user + system) of the commands run so far."""
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    return ru.ru_utime + ru.ru_stime


def scratch(build, shared):
    root = tempfile.mkdtemp(prefix="phc_readme.")
    work = os.path.join(root, "checkout")
    os.mkdir(work)
    source = os.path.dirname(os.path.abspath(README))
    for name in ("measurements", "tests", "notebooks_c", "scripts", "fit", "model", "README.md"):
        os.symlink(os.path.join(source, name), os.path.join(work, name))
    os.symlink(os.path.abspath(build), os.path.join(work, "build"))
    if shared and os.path.isdir(shared):
        os.symlink(os.path.abspath(os.path.join(shared, "..")), os.path.join(root, "shared"))
    return root, work


def main():
    global README
    argv = sys.argv[1:]
    only = select = exclude = None
    as_test = "--as-test" in argv
    if as_test:
        argv.remove("--as-test")
    for flag in ("--only", "--commands", "--other-than"):
        if flag in argv:
            k = argv.index(flag)
            if k + 1 >= len(argv):
                print(f"{flag} needs a value")
                return 2
            value = argv[k + 1]
            del argv[k:k + 2]
            if flag == "--only":
                only = int(value)
            elif flag == "--commands":
                select = re.compile(value)
            else:
                exclude = re.compile(value)
    args = [a for a in argv if not a.startswith("--")]
    if len(args) < 2:
        print(__doc__)
        return 2
    README, build = args[0], args[1]
    shared = args[2] if len(args) > 2 else ""
    have_shared = bool(shared) and os.path.isdir(shared)
    if as_test and select is None:
        print("--as-test needs --commands")
        return 2
    passed = failed = skipped = 0
    self_skipped = 0
    root, work = scratch(build, shared)
    ran = {}
    try:
        for line_no, lang, body, marker in parse(README):
            if lang:
                continue  # yaml, sh, ... are inputs, not outputs
            if only is not None and line_no != only:
                continue
            name = f"README.md:{line_no}"
            if marker is None:
                failed += 1
                print(f"not ok - {name}: an output block without <!-- output: COMMAND --> "
                      f"or <!-- not output: why --> before it")
                continue
            if marker[0] == "not output":
                continue
            command, *options = [p.strip() for p in marker[1].split("|")]
            if select is not None and not select.match(command):
                continue
            if exclude is not None and exclude.match(command):
                continue
            want_exit = 0
            for o in options:
                if o.startswith("exit="):
                    want_exit = int(o[5:])
            no_data = "skip-without-shared" in options and not have_shared
            if no_data and not as_test:
                skipped += 1
                print(f"ok - {name} # SKIP no shared data folder: {command}")
                continue
            t0 = time.time()
            c0 = children_cpu()
            key = (command, "stderr" in options)
            if key in ran:
                proc = ran[key]  # a test program that writes nothing: its output again
            else:
                proc = subprocess.run(["/bin/sh", "-c", command + (" 2>&1" if "stderr" in options else "")],
                                      cwd=work, stdout=subprocess.PIPE, env=QUICK_ENV,
                                      stderr=None if "stderr" in options else subprocess.PIPE,
                                      timeout=1800)
                if READ_ONLY_TEST.match(command):
                    ran[key] = proc
            seconds = time.time() - t0
            cpu = children_cpu() - c0
            got = proc.stdout.decode("utf-8", "replace").rstrip("\n").split("\n")
            got = [g.rstrip() for g in got]
            want = [w.rstrip() for w in body if not w.startswith("$ ")]
            if "timings" in options:
                got = [mask_timing(g) for g in got]
                want = [w if w == "..." else mask_timing(w) for w in want]
            if as_test and proc.returncode == 77:
                self_skipped += 1
                print(f"ok - {name} # SKIP the program skipped itself (exit 77): {command}\n"
                      + proc.stdout.decode("utf-8", "replace")[-600:])
                continue
            problems = []
            if no_data:
                if proc.returncode != want_exit:
                    failed += 1
                    print(f"not ok - {name}: {command}: exit code {proc.returncode}, expected {want_exit}\n"
                          + (proc.stderr or b"").decode("utf-8", "replace")[-600:])
                else:
                    skipped += 1
                    print(f"ok - {name} # SKIP comparison (no shared data folder), exit code {proc.returncode}: {command}")
                continue
            if proc.returncode != want_exit:
                problems.append(f"exit code {proc.returncode}, expected {want_exit}")
                if proc.stderr:
                    problems.append("stderr: " + proc.stderr.decode("utf-8", "replace")[-600:])
            if not block_matches(want, got):
                diff = "\n".join(difflib.unified_diff(want, got, "README", "now", lineterm="", n=1))
                problems.append("output differs:\n" + diff)
            if problems:
                failed += 1
                print(f"not ok - {name}: {command} ({seconds:.1f} s, CPU {cpu:.1f} s)\n  " + "\n  ".join(problems))
            else:
                passed += 1
                print(f"ok - {name}: {command} ({seconds:.1f} s, CPU {cpu:.1f} s)")
    finally:
        shutil.rmtree(root, ignore_errors=True)
    if select is not None and passed + failed + skipped == 0:
        failed += 1
        print(f"not ok - no output block of a command matching {select.pattern!r} in {README}")
    print(f"{passed} passed, {failed} failed, {skipped + self_skipped} skipped")
    if failed:
        return 1
    return 77 if as_test and self_skipped and passed == 0 else 0


if __name__ == "__main__":
    sys.exit(main())
