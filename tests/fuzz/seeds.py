#!/usr/bin/python3
"""Seed corpora for the libFuzzer harnesses (tests/fuzz), built from what the
repository already has; nothing here is real data from ../shared/data.

    python3 seeds.py SOURCE_DIR OUT_DIR [--cases DIR]

writes OUT_DIR/<harness>/<seed> for every harness of tests/fuzz and
OUT_DIR/<harness>.dict (libFuzzer dictionaries) where useful.  Sources:
  - measurements/examples/**: the example configs and their tables, plant
    graph, probe table and readings (tables cut to their first 40 lines);
  - tests/bad_inputs/plant_graphs/*: the malformed plant-graph files;
  - --cases DIR: the files tests/bad_inputs/test_bad_inputs.sh writes for its
    cases (it copies them to $PHC_BAD_INPUTS_KEEP);
  - the README's yaml blocks;
  - the string literals of the unit tests of each reader (tests/unit/
    test_table.c, test_yaml_doc.c, test_rsml.c, test_baad.c, test_units.c,
    test_expression.c, test_plant_io.c), adjacent literals and string
    macros joined as the compiler joins them;
  - the example seedling graph (a native CSV) converted to the paper, SWC
    and TreeQSM formats, so that every plant format has a valid seed.
A seed is kept once (same bytes, same harness) and is at most 64 KiB.
"""
import argparse
import hashlib
import math
import os
import re
import sys

MAX_SEED = 64 * 1024
TABLE_LINES = 40


class Corpus:
    def __init__(self, out):
        self.out = out
        self.seen = set()
        self.count = {}

    def add(self, harness, data, label):
        if isinstance(data, str):
            data = data.encode("utf-8", "surrogateescape")
        if not data or len(data) > MAX_SEED:
            return
        key = (harness, hashlib.sha1(data).hexdigest())
        if key in self.seen:
            return
        self.seen.add(key)
        d = os.path.join(self.out, harness)
        os.makedirs(d, exist_ok=True)
        label = re.sub(r"[^A-Za-z0-9._-]+", "_", label)[:60]
        with open(os.path.join(d, "%s-%s" % (label, key[1][:10])), "wb") as f:
            f.write(data)
        self.count[harness] = self.count.get(harness, 0) + 1


def read(path):
    with open(path, "rb") as f:
        return f.read().decode("utf-8", "surrogateescape")


def head(text, n=TABLE_LINES):
    lines = text.split("\n")
    return "\n".join(lines[:n]) + ("\n" if len(lines) > n else "")


# ---- C string literals ------------------------------------------------------

ESCAPES = {"n": "\n", "t": "\t", "r": "\r", "0": "\0", "\\": "\\", '"': '"', "'": "'",
           "a": "\a", "b": "\b", "f": "\f", "v": "\v", "?": "?"}


def c_tokens(src):
    """Yields ('s', text) for string literals and ('i', name) / ('p', char)."""
    i, n = 0, len(src)
    while i < n:
        c = src[i]
        if src.startswith("//", i):
            i = src.find("\n", i)
            i = n if i < 0 else i
        elif src.startswith("/*", i):
            i = src.find("*/", i + 2)
            i = n if i < 0 else i + 2
        elif c == '"':
            i += 1
            buf = []
            while i < n and src[i] != '"':
                if src[i] == "\\" and i + 1 < n:
                    e = src[i + 1]
                    if e == "x":
                        m = re.match(r"[0-9a-fA-F]+", src[i + 2:])
                        buf.append(chr(int(m.group(0), 16) & 0xFF) if m else "x")
                        i += 2 + (len(m.group(0)) if m else 0)
                        continue
                    if e in "01234567":
                        m = re.match(r"[0-7]{1,3}", src[i + 1:])
                        buf.append(chr(int(m.group(0), 8) & 0xFF))
                        i += 1 + len(m.group(0))
                        continue
                    buf.append(ESCAPES.get(e, e))
                    i += 2
                else:
                    buf.append(src[i])
                    i += 1
            i += 1
            yield ("s", "".join(buf))
        elif c == "'":
            j = i + 1
            while j < n and src[j] != "'":
                j += 2 if src[j] == "\\" else 1
            i = j + 1
            yield ("p", "'")
        elif c.isalpha() or c == "_":
            m = re.match(r"[A-Za-z_0-9]+", src[i:])
            yield ("i", m.group(0))
            i += len(m.group(0))
        elif c.isspace():
            i += 1
        else:
            yield ("p", c)
            i += 1


def c_literals(path):
    """The file's string literals, adjacent literals and string macros joined;
    also returns {name: text} for `static const char *name = "...";` and
    `#define NAME "..."`."""
    src = read(path)
    macros = {}
    for m in re.finditer(r'^#define\s+([A-Z_][A-Z_0-9]*)\s+((?:"(?:[^"\\\n]|\\.)*"\s*)+)',
                         src, re.M):
        macros[m.group(1)] = "".join(t[1] for t in c_tokens(m.group(2)) if t[0] == "s")
    body = re.sub(r"^#.*$", "", src, flags=re.M)
    toks = list(c_tokens(body))
    literals, variables = [], {}
    i = 0
    while i < len(toks):
        kind, text = toks[i]
        if kind == "s" or (kind == "i" and text in macros):
            parts = []
            while i < len(toks) and (toks[i][0] == "s" or (toks[i][0] == "i" and toks[i][1] in macros)):
                parts.append(toks[i][1] if toks[i][0] == "s" else macros[toks[i][1]])
                i += 1
            joined = "".join(parts)
            literals.append(joined)
            # `NAME = "..." ;`
            if i < len(toks) and toks[i] == ("p", ";") and i - len(parts) >= 2:
                before = toks[i - len(parts) - 2: i - len(parts)]
                if before[1] == ("p", "=") and before[0][0] == "i":
                    variables[before[0][1]] = joined
            continue
        i += 1
    return literals, variables


# ---- plant graphs: the example seedling in the other formats ----------------

def native_rows(text, limit=30):
    rows, header = [], None
    for line in text.split("\n"):
        if not line.strip() or line.startswith("#"):
            continue
        cells = line.split(",")
        if header is None:
            header = cells
            continue
        r = dict(zip(header, cells))
        rows.append(r)
        if len(rows) == limit:
            break
    # keep a connected prefix: a row whose parent is not kept is dropped
    kept, ids = [], set()
    for r in rows:
        if r["parent"] in ("-1", "") or r["parent"] in ids:
            kept.append(r)
            ids.add(r["id"])
    return kept


def to_formats(rows):
    idx = {r["id"]: k for k, r in enumerate(rows)}
    f = lambda r, k: float(r[k])
    g = lambda x: repr(x)
    paper = ["verts %d" % len(rows)]
    for k, r in enumerate(rows):
        paper.append("%d,%s,%s,%s,%s,%s" % (k, g(f(r, "x_tail")), g(f(r, "y_tail")), g(f(r, "z_tail")),
                                             g(f(r, "radius")), r.get("leaf", "0")))
    edges = [(idx[r["parent"]], k) for k, r in enumerate(rows) if r["parent"] not in ("-1", "")]
    paper.append("edges %d" % len(edges))
    paper += ["%d,%d" % e for e in edges]
    swc = ["# the example seedling (measurements/examples/weight_curve/seedling.csv), micrometres"]
    root = rows[0]
    swc.append("1 1 %s %s %s %s -1" % tuple(g(f(root, k) * 1e6) for k in ("x_head", "y_head", "z_head", "radius")))
    for k, r in enumerate(rows):
        parent = 1 if r["parent"] in ("-1", "") else idx[r["parent"]] + 2
        swc.append("%d 3 %s %s %s %s %d" % (k + 2, g(f(r, "x_tail") * 1e6), g(f(r, "y_tail") * 1e6),
                                             g(f(r, "z_tail") * 1e6), g(f(r, "radius") * 1e6), parent))
    qsm = []
    for k, r in enumerate(rows):
        h = [f(r, "x_head"), f(r, "y_head"), f(r, "z_head")]
        t = [f(r, "x_tail"), f(r, "y_tail"), f(r, "z_tail")]
        length = math.sqrt(sum((a - b) ** 2 for a, b in zip(t, h)))
        axis = [(a - b) / length for a, b in zip(t, h)]
        parent = 0 if r["parent"] in ("-1", "") else idx[r["parent"]] + 1
        cols = [f(r, "radius"), length] + h + axis + [parent, 0, 0, f(r, "radius"), 1, 0, k + 1]
        qsm.append("\t".join(("%d" % c) if isinstance(c, int) else g(c) for c in cols))
    return "\n".join(paper) + "\n", "\n".join(swc) + "\n", "\n".join(qsm) + "\n"


# ---- configs with the files they name ---------------------------------------

NAME_RE = re.compile(r"[A-Za-z0-9._-]+\.(?:csv|txt|swc|rsml|tsv|dat)\b")


def config_seed(yaml_text, folder, names_seen=None):
    """The config with each file it names (that exists in `folder`) appended
    as a "%% NAME" part, cut to its first lines; paths are reduced to their
    file names."""
    parts, used = [], []
    text = yaml_text
    for m in re.finditer(r"((?:[A-Za-z0-9._-]*/)*)(" + NAME_RE.pattern + ")", yaml_text):
        name = m.group(2)
        if name in used or len(used) >= 7:
            continue
        path = os.path.join(folder, m.group(1) + name) if folder else None
        if path and os.path.isfile(path):
            used.append(name)
            parts.append("%% " + name + "\n" + head(read(path), 30))
    for name in used:
        text = re.sub(r"(?:[A-Za-z0-9._-]*/)+" + re.escape(name), name, text)
    return text + ("\n" if not text.endswith("\n") else "") + "".join(
        p if p.endswith("\n") else p + "\n" for p in parts)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("source")
    ap.add_argument("out")
    ap.add_argument("--cases", help="files written by tests/bad_inputs/test_bad_inputs.sh")
    a = ap.parse_args()
    src = os.path.abspath(a.source)
    c = Corpus(a.out)
    yamls = []      # (label, text, folder)
    csvs = []       # (label, text)
    expressions, units = set(), set()

    # examples
    ex = os.path.join(src, "measurements", "examples")
    for root, _, files in sorted(os.walk(ex)):
        for fn in sorted(files):
            p = os.path.join(root, fn)
            label = "ex_" + fn
            if fn.endswith(".yaml"):
                yamls.append((label, read(p), root))
            elif fn.endswith(".csv"):
                csvs.append((label, head(read(p))))
    # bad-input cases
    if a.cases and os.path.isdir(a.cases):
        for fn in sorted(os.listdir(a.cases)):
            p = os.path.join(a.cases, fn)
            if not os.path.isfile(p):
                continue
            if fn.endswith(".yaml"):
                yamls.append(("bad_" + fn, read(p), a.cases))
            elif fn.endswith(".csv"):
                csvs.append(("bad_" + fn, head(read(p))))
    # README yaml blocks
    readme = read(os.path.join(src, "README.md"))
    for k, m in enumerate(re.finditer(r"^```yaml\n(.*?)^```", readme, re.M | re.S)):
        yamls.append(("readme_%d" % k, m.group(1), ex))

    wcg = set()
    for label, text, folder in yamls:
        # alias bombs (test_yaml_doc.c) are the expansion cap's unit test:
        # each run of one costs seconds, which a short fuzzing run cannot spare
        if text.count("*") > 20:
            continue
        c.add("fuzz_yaml", text, label)
        # the plant-graph cases through a config: one per format (the plant
        # harnesses have them all), as each config load costs ~0.1 s
        m = re.match(r"bad_wcg_([a-z]+)_", label)
        if m:
            if m.group(1) in wcg:
                continue
            wcg.add(m.group(1))
        c.add("fuzz_config", config_seed(text, folder), label)
        for m in re.finditer(r"expression:\s*\"((?:[^\"\\]|\\.)*)\"", text):
            expressions.add(m.group(1))
        for m in re.finditer(r"unit:\s*\"?([^\",}\n#]+)", text):
            units.add(m.group(1).strip())
    for label, text in csvs:
        c.add("fuzz_table", text, label)

    # plant graphs
    pg = os.path.join(src, "tests", "bad_inputs", "plant_graphs")
    for fn in sorted(os.listdir(pg)) if os.path.isdir(pg) else []:
        text = read(os.path.join(pg, fn))
        for prefix, harness in (("paper", "fuzz_plant_paper"), ("treeqsm", "fuzz_plant_treeqsm"),
                                ("swc", "fuzz_plant_swc"), ("native", "fuzz_plant_native")):
            if fn.startswith(prefix):
                c.add(harness, text, "bad_" + fn)
        if fn.startswith("native"):
            c.add("fuzz_table", text, "bad_" + fn)
    seedling = os.path.join(ex, "weight_curve", "seedling.csv")
    if os.path.isfile(seedling):
        text = read(seedling)
        c.add("fuzz_plant_native", head(text, 25), "ex_seedling_head")
        for n in (2, 5, 30):
            paper, swc, qsm = to_formats(native_rows(text, n))
            c.add("fuzz_plant_paper", paper, "ex_seedling_%d" % n)
            c.add("fuzz_plant_swc", swc, "ex_seedling_%d" % n)
            c.add("fuzz_plant_treeqsm", qsm, "ex_seedling_%d" % n)

    # soil probes: the example's table and readings, columns renamed to the
    # harness's (id, lat, lon, depth, sigma / x, y; t, probe, value)
    sp = os.path.join(ex, "soil_probe")
    if os.path.isdir(sp):
        probes = head(read(os.path.join(sp, "probes.csv")), 12)
        readings = head(read(os.path.join(sp, "readings.csv")), 30).replace("time_h,probe,theta", "t,probe,value")
        c.add("fuzz_soil_probes", probes + "%% readings.csv\n" + readings, "ex_soil_probe")
        c.add("fuzz_soil_probes", probes, "ex_soil_probe_table")
    c.add("fuzz_soil_probes", "id,x,y,depth\nP1,0.5,0.5,0.1\nP2,0.2,0.8,0.3\n%% readings.csv\n"
          "t,probe,value\n0,P1,0.31\n0,P2,0.30\n3600,P1,0.33\n", "grid_frame")
    if a.cases and os.path.isdir(a.cases):
        for fn in sorted(os.listdir(a.cases)):
            if fn.startswith(("probes", "sp_")) and fn.endswith(".csv"):
                c.add("fuzz_soil_probes", read(os.path.join(a.cases, fn)), "bad_" + fn)

    # unit-test literals
    unit = os.path.join(src, "tests", "unit")

    def lits(name):
        p = os.path.join(unit, name)
        return c_literals(p) if os.path.isfile(p) else ([], {})

    for s in lits("test_table.c")[0]:
        if "\n" in s or "," in s:
            c.add("fuzz_table", s, "unit_table")
    for s in lits("test_yaml_doc.c")[0]:
        if (":" in s or "\n" in s or "-" in s) and s.count("*") <= 20:
            c.add("fuzz_yaml", s, "unit_yaml")
    for s in lits("test_rsml.c")[0]:
        if "<" in s:
            c.add("fuzz_rsml", s, "unit_rsml")
    for s in lits("test_units.c")[0]:
        if 0 < len(s) < 60 and "\n" not in s and "%" not in s:
            units.add(s)
    for s in lits("test_expression.c")[0]:
        if 0 < len(s) < 400 and "\n" not in s and "%" not in s:
            expressions.add(s)
    for s in lits("test_plant_io.c")[0]:
        if s.startswith("verts"):
            c.add("fuzz_plant_paper", s, "unit_plant")
        elif "\t" in s and "\n" in s:
            c.add("fuzz_plant_treeqsm", s, "unit_plant")
        elif s.startswith(("# unit", "id,parent")):
            c.add("fuzz_plant_native", s, "unit_plant")
        elif "\n" in s and re.search(r"^\s*\d+\s+\d+\s+\S+\s+\S+\s+\S+\s+\S+\s+-?\d+", s, re.M):
            c.add("fuzz_plant_swc", s, "unit_plant")
    # BAAD: the unit test's study files, whole and one file changed at a time
    blits, bvars = lits("test_baad.c")
    parts = {k: bvars.get(v) for k, v in (("data", "good_data"), ("match", "good_match"),
                                          ("new", "good_new"), ("defs", "defs_csv"))}

    def study(data, match, new, defs):
        s = data if data.endswith("\n") else data + "\n"
        for name, text in (("dataMatchColumns.csv", match), ("dataNew.csv", new),
                           ("variableDefinitions.csv", defs)):
            if text is not None:
                s += "%% " + name + "\n" + (text if text.endswith("\n") else text + "\n")
        return s

    if all(parts.values()):
        c.add("fuzz_baad", study(parts["data"], parts["match"], parts["new"], parts["defs"]), "unit_baad_good")
        c.add("fuzz_baad", study(parts["data"], parts["match"], None, parts["defs"]), "unit_baad_nonew")
        # expect_error("Name", DATA, MATCH, NEW, ...): each argument a variable,
        # NULL (file absent) or edit(VARIABLE, "old", "new")
        toks = list(c_tokens(re.sub(r"^#.*$", "", read(os.path.join(unit, "test_baad.c")), flags=re.M)))
        for i in range(len(toks) - 2):
            if toks[i] != ("i", "expect_error") or toks[i + 1] != ("p", "(") or toks[i + 2][0] != "s":
                continue
            args, j = [], i + 4
            while len(args) < 3 and j < len(toks):
                if toks[j] == ("i", "NULL"):
                    args.append(None)
                    j += 2
                elif toks[j] == ("i", "edit") and j + 7 < len(toks) and toks[j + 2][1] in bvars:
                    base = bvars[toks[j + 2][1]]
                    old_s, new_s = toks[j + 4][1], toks[j + 6][1]
                    args.append(base.replace(old_s, new_s, 1))
                    j += 9
                elif toks[j][0] == "i" and toks[j][1] in bvars:
                    args.append(bvars[toks[j][1]])
                    j += 2
                else:
                    break
            if len(args) == 3:
                c.add("fuzz_baad", study(args[0] or "", args[1], args[2], parts["defs"]),
                      "unit_baad_" + toks[i + 2][1])
        for s in blits:
            if "\n" in s:
                c.add("fuzz_table", s, "unit_baad")
        for m in re.finditer(r'^[^,\n]*,[^,\n]*,"?([^,"\n]+)"?,', parts["match"], re.M):
            units.add(m.group(1))

    for k, e in enumerate(sorted(expressions)):
        c.add("fuzz_expression", e, "expr_%d" % k)
    targets = 14  # the entries of fuzz_units.c's targets[]
    for k, u in enumerate(sorted(units)):
        if u in ("NA", "unit_in"):
            continue
        for t in (k % targets, (k * 5 + 3) % targets):
            c.add("fuzz_units", bytes([t]) + u.encode("utf-8", "surrogateescape"), "unit_%d_%d" % (k, t))

    # dictionaries: the keys and kinds the configs use, XML names of RSML
    keys = set()
    for _, text, _ in yamls:
        keys.update(re.findall(r"^\s*-?\s*([A-Za-z_][A-Za-z_0-9]*):", text, re.M))
        keys.update(re.findall(r"[{,]\s*([A-Za-z_][A-Za-z_0-9]*):", text))
        keys.update(re.findall(r"kind:\s*([A-Za-z_]+)", text))
    with open(os.path.join(a.out, "fuzz_config.dict"), "w") as f:
        for k in sorted(keys):
            f.write('"%s:"\n' % k)
        for k in ("%% data.csv\\x0a", "data.csv", "{value: 1}", "lower: 0", "- kind: "):
            f.write('"%s"\n' % k)
    with open(os.path.join(a.out, "fuzz_rsml.dict"), "w") as f:
        for k in ("rsml", "metadata", "unit", "resolution", "scene", "plant", "root", "geometry",
                  "polyline", "point", "function", "functions", "sample", "diameter", "domain",
                  "x=\\\"1\\\"", "y=\\\"2\\\"", "z=\\\"3\\\"", "ID", "label", "value"):
            f.write('"%s"\n' % k)
    for h in sorted(c.count):
        print("seeds: %-20s %4d" % (h, c.count[h]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
