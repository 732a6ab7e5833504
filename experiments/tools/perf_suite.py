"""The performance suite: every estimator's samples per second on scenes that cover what a
renderer's common path must be fast at, and `pt` against Mitsuba 3 side by side.

    python3 experiments/tools/perf_suite.py [--repeats 3] [--only envmap,water]
        [--mitsuba /work/venv-mitsuba/bin/python] [--out results/perf] [--binary PATH]

Each scene renders with `mltbench render` (2 threads, its own resolution and max_depth), once
per estimator and repeat; the table gives the median of the summary line's samples per second
(pt, bdpt: camera samples; lt: light paths; pssmlt, mmlt: mutations, bootstrap included;
ppm: light paths of the photon passes). With --mitsuba (a Python that has the `mitsuba`
package: CROSSCHECK.md), `pt` is also timed against Mitsuba 3's llvm_ad_rgb by
crosscheck_mitsuba.py, --repeats back-to-back pairs per scene (Mitsuba's JIT warm-up
excluded), and the table gives the median ratio of camera paths per second (not for the
scenes of NO_MITSUBA, which Mitsuba 3 cannot load). Writes
OUT/README.md and OUT/perf.csv. The meshes two scenes need are written on first use
(experiments/perf/meshes/, not committed: one has 330k triangles).

With --smallvcm PATH (a SmallVCM build: docs/performance.md says how it was built), `bdpt`
is also timed against SmallVCM's `bpt` on smallvcm-cbox, --repeats back-to-back pairs of
`smallvcm -a bpt -s 2 -i 6` and `mltbench render smallvcm-cbox.xml -e bdpt --spp 6`: the same
512 x 512 x 6 path pairs, compared by each process's user + system CPU seconds (scene
loading and image writing included on both sides), so the ratio does not depend on how either
spreads its work over the cores. Written to the table's notes and to perf.csv.

With --bitterli DIR (the folder of Bitterli's scenes, e.g. ../shared/scenes/bitterli), the
three scenes there are timed too, at a quarter of their width and height (`BITTERLI`): scenes the
suite was not written for. Their pt / Mitsuba ratios get a geometric mean of their own.

--binary times another build (e.g. an older commit's, built with `git worktree` and its own
CARGO_TARGET_DIR) on this checkout's scenes, for before/after tables; the Mitsuba column
always times this checkout's build (crosscheck_mitsuba.py). --against OLD alternates the
build with OLD render by render (OLD, new, OLD, new, ... --repeats pairs per cell), so that a
machine whose speed drifts moves both alike, and writes OUT/against.md: both medians, their
ratio and the lowest and highest ratio of a pair per cell (a median ratio inside that range
of 1.00 is noise). The pt / Mitsuba column likewise gives the pairs' range beside the
median.

Needs only the standard library (and a built `target/release/mltbench`).
"""

import argparse
import csv
import math
import os
import statistics
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from crosscheck_mitsuba import MLTBENCH_LINE  # noqa: E402  (the render summary's format)

REPO = Path(__file__).resolve().parents[2]
BINARY = REPO / "target" / "release" / "mltbench"
MESHES = REPO / "experiments" / "perf" / "meshes"

# (name, scene file, what it covers)
SUITE = [
    ("cbox", "experiments/scenes/cbox.xml", "diffuse, one area light, 36 triangles"),
    ("cbox-spheres", "experiments/scenes/cbox-spheres.xml", "mirror and glass analytic spheres"),
    ("cbox-glossy", "experiments/perf/cbox-glossy.xml", "rough conductor, rough plastic, twosided walls"),
    ("envmap", "experiments/scenes/envmap-spheres.xml", "lat-long environment map, three spheres"),
    ("water", "experiments/perf/water.xml", "4050-triangle dielectric mesh, textured floor"),
    ("displaced", "experiments/perf/displaced-sphere.xml", "330k-triangle mesh in the Cornell box"),
    ("textures", "experiments/scenes/textures.xml", "bitmap and procedural textures"),
    ("dof", "experiments/scenes/cbox-dof.xml", "thin-lens camera"),
    ("point", "experiments/scenes/cbox-point.xml", "point light"),
    ("smallvcm-cbox", "experiments/perf/smallvcm-cbox.xml",
     "SmallVCM's point-light box (its -s 2): bdpt against smallvcm -a bpt"),
]

# Bitterli's scenes (`--bitterli DIR`, DIR holding veach-mis/, veach-bidir/, cornell-box/,
# each with scene.xml): scenes the suite was not written for, rendered at a quarter of their
# width and height to keep each render to seconds. Reported beside the suite, not in its mean.
BITTERLI = [
    ("veach-mis", "sphere lights, rough conductor plates, 52 triangles", ["res_x=320", "res_y=180"]),
    ("veach-bidir", "lamp in a shade, glass egg, 11.5k triangles", ["res_x=256", "res_y=256"]),
    ("cornell-box", "the classic box, twosided walls, 36 triangles", ["res_x=256", "res_y=256"]),
]

# Scenes Mitsuba 3 cannot load, and why: no pt / Mitsuba ratio for them.
NO_MITSUBA = {"smallvcm-cbox": "Mitsuba 3 has no phong BSDF"}

# (estimator label, mltbench arguments, spp): spp keeps every render to a few seconds.
ESTIMATORS = [
    ("pt", ["-e", "pt"], 64),
    ("lt", ["-e", "lt"], 16),
    ("bdpt", ["-e", "bdpt"], 8),
    ("pssmlt", ["-e", "pssmlt", "--set", "base=bdpt"], 8),
    ("mmlt", ["-e", "mmlt"], 16),
    ("ppm", ["-e", "ppm"], 16),
]


# ---------------------------------------------------------------- meshes


def write_ply(path, vertices, faces):
    """A binary little-endian PLY of float vertices and triangle faces."""
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"element vertex {len(vertices)}\n"
        "property float x\nproperty float y\nproperty float z\n"
        f"element face {len(faces)}\n"
        "property list uchar int vertex_indices\nend_header\n"
    )
    body = bytearray()
    for v in vertices:
        body += struct.pack("<3f", *v)
    for f in faces:
        body += struct.pack("<B3i", 3, *f)
    tmp = path.with_suffix(".tmp")
    tmp.write_bytes(header.encode("ascii") + bytes(body))
    tmp.replace(path)


def water_mesh(n=45):
    """An n x n grid of quads over [-1.5, 1.5]^2 at height 0 with ripples of 2 cm."""
    vertices = []
    for j in range(n + 1):
        for i in range(n + 1):
            x, z = -1.5 + 3.0 * i / n, -1.5 + 3.0 * j / n
            y = 0.02 * (math.sin(4.1 * x + 1.3 * z) + math.sin(2.3 * z - 3.7 * x + 0.5))
            vertices.append((x, y, z))
    faces = []
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            b, c, d = a + 1, a + n + 1, a + n + 2
            # Counter-clockwise seen from above: the faces' front looks up.
            faces += [(a, c, b), (b, c, d)]
    return vertices, faces


def displaced_sphere_mesh(rings=288, segments=576):
    """A unit sphere, displaced radially by two octaves of bumps, as rings x segments quads
    (one triangle per quad at the poles): 330,624 triangles."""
    vertices = [(0.0, 1.0, 0.0)]
    for r in range(1, rings):
        theta = math.pi * r / rings
        for s in range(segments):
            phi = 2 * math.pi * s / segments
            d = 1 + 0.06 * math.sin(9 * theta) * math.cos(7 * phi) + 0.015 * math.sin(
                41 * theta + 3 * phi
            ) * math.sin(37 * phi)
            vertices.append(
                (d * math.sin(theta) * math.cos(phi), d * math.cos(theta), d * math.sin(theta) * math.sin(phi))
            )
    vertices.append((0.0, -1.0, 0.0))
    south = len(vertices) - 1

    def ring(r, s):  # vertex index of ring r (1..rings-1), segment s
        return 1 + (r - 1) * segments + s % segments

    faces = []
    for s in range(segments):
        faces.append((0, ring(1, s + 1), ring(1, s)))
        faces.append((south, ring(rings - 1, s), ring(rings - 1, s + 1)))
    for r in range(1, rings - 1):
        for s in range(segments):
            a, b = ring(r, s), ring(r, s + 1)
            c, d = ring(r + 1, s), ring(r + 1, s + 1)
            faces += [(a, b, c), (b, d, c)]
    return vertices, faces


def ensure_meshes():
    MESHES.mkdir(parents=True, exist_ok=True)
    for name, make in [("water.ply", water_mesh), ("displaced-sphere.ply", displaced_sphere_mesh)]:
        path = MESHES / name
        if not path.exists():
            print(f"writing {path.relative_to(REPO)}", file=sys.stderr)
            write_ply(path, *make())


# ---------------------------------------------------------------- runs


def define_args(defines):
    """`-D NAME=VALUE` arguments (both renderers' command lines take them)."""
    return [a for d in defines for a in ("-D", d)]


def render_rate(binary, scene, args, spp, threads, tmp, defines=()):
    """Samples per second from one `mltbench render`, or an error message."""
    out = Path(tmp) / "perf.exr"
    cmd = [str(binary), "render", str(REPO / scene), *args, *define_args(defines), "--spp", str(spp)]
    cmd += ["--threads", str(threads), "-o", str(out)]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        lines = proc.stderr.strip().splitlines()
        return None, (lines[-1] if lines else f"exit code {proc.returncode}")
    for line in proc.stderr.splitlines():
        m = MLTBENCH_LINE.match(line)
        if m:
            return float(m["msps"]), None
    return None, "no summary line in mltbench's output"


def mitsuba_ratio(python, scene, threads, tmp, defines=()):
    """mltbench / Mitsuba llvm_ad_rgb camera paths per second for one back-to-back pair."""
    table = Path(tmp) / "crosscheck.csv"
    table.unlink(missing_ok=True)
    cmd = [python, str(REPO / "experiments/tools/crosscheck_mitsuba.py"), str(REPO / scene)]
    cmd += define_args(defines)
    cmd += ["--spp", "64", "--variant", "llvm_ad_rgb", "--threads", str(threads), "--csv", str(table)]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0 or not table.exists():
        lines = (proc.stderr or proc.stdout).strip().splitlines()
        return None, (lines[-1] if lines else f"exit code {proc.returncode}")
    with table.open() as f:
        row = next(csv.DictReader(f))
    return (
        float(row["throughput_ratio"]),
        float(row["mltbench_mpaths_s"]),
        float(row["mitsuba_mpaths_s"]),
    ), None


def child_cpu_seconds(cmd, env=None):
    """Runs `cmd` to completion; (user + system CPU seconds of that process, error or None)."""
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env)
    # wait4 reports the rusage of this child alone (not of earlier children).
    _, status, usage = os.wait4(proc.pid, 0)
    stderr = proc.stderr.read().decode(errors="replace")
    proc.stderr.close()
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode != 0:
        lines = stderr.strip().splitlines()
        return None, (lines[-1] if lines else f"exit code {proc.returncode}")
    return usage.ru_utime + usage.ru_stime, None


# The SmallVCM comparison: its scene 2 at its 512 x 512, six iterations (path pairs per pixel).
SMALLVCM_SCENE = "experiments/perf/smallvcm-cbox.xml"
SMALLVCM_ITERATIONS = 6


def smallvcm_pair(binary, smallvcm, threads, tmp):
    """CPU seconds of SmallVCM's bpt and of mltbench's bdpt on the same path pairs, run in
    turn: ((smallvcm_s, mltbench_s), error)."""
    env = dict(os.environ, OMP_NUM_THREADS=str(threads))
    theirs, error = child_cpu_seconds(
        [str(smallvcm), "-a", "bpt", "-s", "2", "-i", str(SMALLVCM_ITERATIONS),
         "-o", str(Path(tmp) / "smallvcm.bmp")], env)
    if theirs is None:
        return None, f"smallvcm: {error}"
    ours, error = child_cpu_seconds(
        [str(binary), "render", str(REPO / SMALLVCM_SCENE), "-e", "bdpt",
         "--spp", str(SMALLVCM_ITERATIONS), "--threads", str(threads),
         "-o", str(Path(tmp) / "smallvcm-bdpt.exr")])
    if ours is None:
        return None, f"mltbench: {error}"
    return (theirs, ours), None


def repeated(repeats, measure):
    """`measure()` (a (result, error) pair) `repeats` times: (results, None), or (results so
    far, the first error)."""
    results = []
    for _ in range(repeats):
        result, error = measure()
        if result is None:
            return results, error
        results.append(result)
    if not results:
        return results, "no repeats"
    return results, None


def main(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--repeats", type=int, default=1, help="renders (and Mitsuba pairs) per cell; medians")
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--only", help="comma-separated scene names of the suite")
    p.add_argument("--estimators", help="comma-separated estimators (default all)")
    p.add_argument("--mitsuba", metavar="PYTHON", help="a Python with the mitsuba package")
    p.add_argument("--smallvcm", type=Path, metavar="PATH",
                   help="a SmallVCM binary: time bdpt against its bpt on smallvcm-cbox (CPU seconds)")
    p.add_argument("--bitterli", type=Path, metavar="DIR",
                   help="also time Bitterli's scenes from DIR (veach-mis/, veach-bidir/, cornell-box/)")
    p.add_argument("--out", type=Path, default=REPO / "results" / "perf")
    p.add_argument("--binary", type=Path, default=BINARY, help="the mltbench build to time")
    p.add_argument("--against", type=Path, metavar="OLD",
                   help="another build, alternated with --binary render by render (against.md)")
    args = p.parse_args(argv)
    if args.against and not args.against.exists():
        print(f"error: --against {args.against} not found", file=sys.stderr)
        return 2
    if args.smallvcm and not args.smallvcm.exists():
        print(f"error: --smallvcm {args.smallvcm} not found", file=sys.stderr)
        return 2
    if not args.binary.exists():
        print(f"error: {args.binary} not found: run `cargo build --release` first", file=sys.stderr)
        return 2
    scenes = [(name, scene, covers, (), False) for name, scene, covers in SUITE]
    if args.only:
        wanted = set(args.only.split(","))
        unknown = wanted - {s[0] for s in SUITE}
        if unknown:
            print(f"error: --only names unknown scenes {sorted(unknown)}; the suite has "
                  f"{[s[0] for s in SUITE]}", file=sys.stderr)
            return 2
        scenes = [s for s in scenes if s[0] in wanted]
    if args.bitterli:
        for name, covers, defines in BITTERLI:
            path = (args.bitterli / name / "scene.xml").resolve()
            if not path.exists():
                print(f"error: --bitterli: {path} not found", file=sys.stderr)
                return 2
            scenes.append((f"bitterli {name}", str(path), covers, defines, True))
    estimators = ESTIMATORS
    if args.estimators:
        wanted = set(args.estimators.split(","))
        estimators = [e for e in ESTIMATORS if e[0] in wanted]
    ensure_meshes()
    args.out.mkdir(parents=True, exist_ok=True)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for name, scene, covers, defines, extra in scenes:
            row = {"scene": name, "file": scene, "covers": covers, "extra": extra}
            for label, est_args, spp in estimators:
                rates, old_rates, error = [], [], None
                for _ in range(args.repeats):
                    if args.against:
                        rate, error = render_rate(args.against, scene, est_args, spp, args.threads, tmp, defines)
                        if rate is None:
                            break
                        old_rates.append(rate)
                    rate, error = render_rate(args.binary, scene, est_args, spp, args.threads, tmp, defines)
                    if rate is None:
                        break
                    rates.append(rate)
                row[label] = statistics.median(rates) if rates and error is None else None
                row[label + "_error"] = error
                if args.against and error is None:
                    row[label + "_against"] = statistics.median(old_rates)
                    # Each pair's ratio: their spread says what a median ratio can tell.
                    row[label + "_pair_ratios"] = [n / o for o, n in zip(old_rates, rates)]
                print(f"{name:14} {label:8} "
                      + (f"{row[label]:.3f} M/s" if row[label] is not None else f"error: {error}")
                      + (f" (against {row[label + '_against']:.3f})" if row.get(label + "_against") else ""),
                      file=sys.stderr)
            if args.mitsuba and name in NO_MITSUBA:
                row["mitsuba_skipped"] = NO_MITSUBA[name]
                print(f"{name:14} mitsuba  skipped: {NO_MITSUBA[name]}", file=sys.stderr)
            elif args.mitsuba:
                pairs, error = repeated(
                    args.repeats, lambda: mitsuba_ratio(args.mitsuba, scene, args.threads, tmp, defines))
                if error is None:
                    row["mitsuba_ratio"] = statistics.median(p[0] for p in pairs)
                    row["mitsuba_ratio_range"] = (min(p[0] for p in pairs), max(p[0] for p in pairs))
                    row["mitsuba_mpaths"] = statistics.median(p[2] for p in pairs)
                    row["pt_pair_mpaths"] = statistics.median(p[1] for p in pairs)
                else:
                    row["mitsuba_error"] = error
                print(f"{name:14} mitsuba  " + (f"ratio {row['mitsuba_ratio']:.2f}" if "mitsuba_ratio" in row
                      else f"error: {error}"), file=sys.stderr)
            if args.smallvcm and scene == SMALLVCM_SCENE:
                pairs, error = repeated(
                    args.repeats, lambda: smallvcm_pair(args.binary, args.smallvcm, args.threads, tmp))
                if error is None:
                    row["smallvcm_cpu_s"] = statistics.median(p[0] for p in pairs)
                    row["bdpt_cpu_s"] = statistics.median(p[1] for p in pairs)
                    row["bdpt_vs_smallvcm"] = statistics.median(p[0] / p[1] for p in pairs)
                    row["smallvcm_pairs"] = pairs
                else:
                    row["smallvcm_error"] = error
                print(f"{name:14} smallvcm "
                      + (f"bdpt / SmallVCM bpt per CPU-second {row['bdpt_vs_smallvcm']:.2f}"
                         if "bdpt_vs_smallvcm" in row else f"error: {error}"), file=sys.stderr)
            rows.append(row)
    write_outputs(args, rows, estimators)
    return 0


def write_against(args, rows, labels):
    """OUT/against.md: per cell the medians of --against and --binary and their ratio."""
    lines = [
        "# Performance suite: two builds alternated",
        "",
        f"`perf_suite.py --repeats {args.repeats} --against {args.against} --binary {args.binary}`, "
        f"{args.threads} threads, {time.strftime('%Y-%m-%d')}: renders of the two builds taken in "
        f"turn, medians of {args.repeats} each, M samples/s as in README.md; old → new (new / old; "
        "the lowest and highest ratio of a pair taken in turn).",
        "",
        "| scene | " + " | ".join(labels) + " |",
        "|---|" + "---|" * len(labels),
    ]
    for r in rows:
        cells = [r["scene"]]
        for k in labels:
            old, new = r.get(k + "_against"), r.get(k)
            pairs = r.get(k + "_pair_ratios") or []
            spread = f"; pairs {min(pairs):.2f}–{max(pairs):.2f}" if len(pairs) > 1 else ""
            cells.append(f"{old:.3f} → {new:.3f} ({new / old:.2f}{spread})" if old and new else "error")
        lines.append("| " + " | ".join(cells) + " |")
    (args.out / "against.md").write_text("\n".join(lines) + "\n")


def write_outputs(args, rows, estimators):
    labels = [e[0] for e in estimators]
    if args.against:
        write_against(args, rows, labels)
    with (args.out / "perf.csv").open("w", newline="") as f:
        fields = ["scene", "file"] + labels + ["mitsuba_mpaths", "pt_pair_mpaths", "mitsuba_ratio",
                                               "smallvcm_cpu_s", "bdpt_cpu_s", "bdpt_vs_smallvcm"]
        w = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow({k: ("" if r.get(k) is None else r.get(k)) for k in fields})
    units = ", ".join(f"{label} {spp} spp" for label, _, spp in estimators)
    lines = [
        "# Performance suite",
        "",
        f"`python3 experiments/tools/perf_suite.py --repeats {args.repeats}"
        + (" --mitsuba PYTHON" if args.mitsuba else "")
        + (" --smallvcm PATH" if args.smallvcm else "")
        + (" --bitterli DIR" if args.bitterli else "")
        + f"`, {args.threads} threads, {time.strftime('%Y-%m-%d')}. Millions of samples per second "
        f"(medians of {args.repeats}; {units}): camera samples for pt and bdpt, light paths for "
        "lt and ppm, mutations for pssmlt (base=bdpt) and mmlt, their bootstrap included."
        + (" pt / Mitsuba: the median ratio of the pairs, in parentheses the lowest and highest."
           if args.mitsuba else ""),
        "",
    ]
    head = "| scene | covers | " + " | ".join(labels)
    rule = "|---|---|" + "---|" * len(labels)
    if args.mitsuba:
        head += " | Mitsuba llvm_ad_rgb | pt / Mitsuba"
        rule += "---|---|"
    lines += [head + " |", rule]
    ratios, extra_ratios = [], []
    for r in rows:
        cells = [r["scene"], r["covers"]]
        cells += [f"{r[k]:.3f}" if r.get(k) is not None else "error" for k in labels]
        if args.mitsuba:
            if "mitsuba_ratio" in r:
                lo, hi = r["mitsuba_ratio_range"]
                cells += [f"{r['mitsuba_mpaths']:.3f}", f"{r['mitsuba_ratio']:.2f} ({lo:.2f}–{hi:.2f})"]
                (extra_ratios if r["extra"] else ratios).append(r["mitsuba_ratio"])
            elif "mitsuba_skipped" in r:
                cells += [f"— ({r['mitsuba_skipped']})", ""]
            else:
                cells += ["error", ""]
        lines.append("| " + " | ".join(cells) + " |")
    def gmean(xs):
        return math.exp(sum(math.log(x) for x in xs) / len(xs))
    if ratios:
        lines += ["", f"Geometric mean of pt / Mitsuba over {len(ratios)} scenes: {gmean(ratios):.2f}."]
    if extra_ratios:
        lines += ["", f"Bitterli's scenes (at a quarter of their width and height, not in the mean above): "
                  f"geometric mean {gmean(extra_ratios):.2f} over {len(extra_ratios)}."]
    for r in rows:
        if "bdpt_vs_smallvcm" in r:
            each = ", ".join(f"{a:.2f} / {b:.2f} s" for a, b in r["smallvcm_pairs"])
            lines += ["", f"`bdpt` against SmallVCM's `bpt` on {r['scene']} ({SMALLVCM_ITERATIONS} "
                      f"path pairs per pixel at 512 x 512, {args.threads} threads, {len(r['smallvcm_pairs'])} "
                      f"pairs taken in turn; CPU seconds SmallVCM / mltbench: {each}): "
                      f"**{r['bdpt_vs_smallvcm']:.2f}×** SmallVCM's path pairs per CPU-second (median)."]
    errors = [(r["scene"], k, r[k + "_error"]) for r in rows for k in labels if r.get(k + "_error")]
    errors += [(r["scene"], "smallvcm", r["smallvcm_error"]) for r in rows if r.get("smallvcm_error")]
    errors += [(r["scene"], "mitsuba", r["mitsuba_error"]) for r in rows if r.get("mitsuba_error")]
    if errors:
        lines += ["", "Errors:", ""] + [f"- {s}, {k}: {e}" for s, k, e in errors]
    (args.out / "README.md").write_text("\n".join(lines) + "\n")
    extra = " and against.md" if args.against else ""
    print(f"wrote {args.out / 'README.md'}, perf.csv{extra}", file=sys.stderr)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
