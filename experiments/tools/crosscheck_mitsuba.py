"""Cross-check an mltbench render against Mitsuba 3 on the same scene file.

Renders SCENE.xml with Mitsuba 3 (pip package `mitsuba`) and with `mltbench render`, at the
same samples per pixel, then prints per-channel means and their ratio (with a standard error),
the relMSE between the two images (docs/DESIGN.md §5) and both throughputs in camera paths per
second. See CROSSCHECK.md beside this file for installing Mitsuba and reading the output.

    /work/venv-mitsuba/bin/python experiments/tools/crosscheck_mitsuba.py \\
        experiments/scenes/cbox.xml --spp 64 [--variant scalar_rgb|llvm_ad_rgb|both]

Each Mitsuba variant renders in a child process (this same file, in worker mode), so a
variant that crashes the interpreter (llvm_ad_rgb with a too-old system libLLVM aborts the
process) is reported, and in the default `auto` mode replaced by scalar_rgb.
"""

import argparse
import csv
import json
import math
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[2]
DEFAULT_BINARY = REPO_ROOT / "target" / "release" / "mltbench"
VENV_HINT = (
    "    python3 -m venv /work/venv-mitsuba\n"
    '    /work/venv-mitsuba/bin/pip install "mitsuba>=3.9,<3.10" numpy\n'
    "    /work/venv-mitsuba/bin/python " + " ".join(sys.argv)
)
LLVM_HINT = (
    "llvm_ad_rgb needs a system libLLVM >= 16 (LLVM 15 aborts in the first render): "
    "`apt-get install libllvm19`, or point DRJIT_LIBLLVM_PATH at a libLLVM.so"
)
# Most camera paths rendered in one launch of a vectorised variant (its wavefront holds all
# of them in memory); a larger spp is rendered as several launches with different seeds,
# averaged.
MAX_LANES = 1 << 24
# The summary line `mltbench render` writes to stderr (src/main.rs).
MLTBENCH_LINE = re.compile(
    r"^(?P<est>\S+): (?P<passes>\d+) passes, (?P<samples>\d+) samples, (?P<secs>[0-9.]+) s "
    r"\((?P<msps>[0-9.]+) M samples/s[^)]*\)(, (?P<dropped>\d+) invalid samples dropped)?"
)


class Failure(Exception):
    """An expected failure: printed as `error: ...` with no traceback."""


# ---------------------------------------------------------------- worker (child process)


def set_llvm_lanes(lanes):
    """Makes Dr.Jit's LLVM backend compile `lanes`-wide kernels for an AVX2 CPU, as on a
    machine without AVX-512 (16 lanes there). Only Dr.Jit's kernels: Mitsuba's ray tracing
    (Embree) picks its own instruction set. Dr.Jit does not expose its
    `jit_llvm_set_target(cpu, features, vector_width)` to Python; it is called from the
    core library directly, before any kernel is compiled, and the width read back."""
    import ctypes
    import drjit as dr

    def fail(why):
        raise SystemExit(f"--llvm-lanes {lanes}: {why} (Dr.Jit {dr.__version__})")

    try:
        core = ctypes.CDLL(str(Path(dr.__file__).parent / "libdrjit-core.so"))
        # C++ mangled names of jit_llvm_set_target and jit_llvm_vector_width.
        set_target = getattr(core, "_Z19jit_llvm_set_targetPKcS0_j")
        vector_width = getattr(core, "_Z21jit_llvm_vector_widthv")
    except (OSError, AttributeError) as e:
        fail(f"cannot reach Dr.Jit's LLVM target settings: {e}")
    set_target.argtypes = [ctypes.c_char_p, ctypes.c_char_p, ctypes.c_uint]
    vector_width.restype = ctypes.c_uint32
    set_target(b"haswell", b"+avx2,+fma,+f16c,+bmi,+bmi2,+lzcnt,+popcnt", lanes)
    if vector_width() != lanes:
        fail(f"Dr.Jit kept {vector_width()} lanes (is its LLVM backend initialised?)")


def worker(job_file):
    """Render one scene with one Mitsuba variant at each spp of the job; write EXRs + JSON."""
    job = json.loads(Path(job_file).read_text())
    import drjit as dr
    import mitsuba as mi
    import numpy as np

    mi.set_variant(job["variant"])
    mi.set_log_level(mi.LogLevel.Warn)
    if job.get("llvm_lanes") and job["variant"].startswith("llvm"):
        set_llvm_lanes(job["llvm_lanes"])
    # The pool's size counts the calling thread, which works too: T means T busy threads.
    # Loading and writing images wait on pool tasks, which a pool of one (the caller, busy
    # waiting) never runs: Mitsuba 3.9 hangs loading an envmap with one thread. Those steps
    # run with at least two; the renders with T.
    io_threads = max(2, job["threads"])
    dr.set_thread_count(io_threads)
    scene_path = job["scene"]
    spps = job["spps"]
    # Scenes that declare `<default name="spp">` take the sample count as a parameter;
    # passing a parameter the scene does not use is an error in Mitsuba.
    declares_spp = re.search(r"\$spp\b", Path(scene_path).read_text()) is not None
    params = dict(job["defines"])
    if declares_spp:
        params["spp"] = str(max(spps))
    t0 = time.perf_counter()
    # Without merging: Mitsuba 3.9 merges shapes of equal BSDFs into one mesh and leaves its
    # bounding box out of the scene's bounding sphere, whose radius bounds a directional
    # light's shadow rays (2R): in a room (experiments/scenes/sun-room.xml) they then stop
    # short of the walls and light what the walls shadow.
    scene = mi.load_file(scene_path, optimize=False, **params)
    load_seconds = time.perf_counter() - t0
    dr.set_thread_count(job["threads"])
    film = scene.sensors()[0].film()
    width, height = (int(v) for v in film.crop_size())
    rfilter = str(film.rfilter()).split("[")[0]
    out = {
        "variant": job["variant"],
        "mitsuba": mi.__version__,
        "drjit": dr.__version__,
        "threads": dr.thread_count(),
        "width": width,
        "height": height,
        "rfilter": rfilter,
        "declares_spp": declares_spp,
        "load_seconds": load_seconds,
        "warmup_seconds": None,
        "runs": [],
    }

    def render(spp):
        # Split into launches of at most MAX_LANES paths; equal-spp passes average exactly.
        lanes_per_spp = width * height
        per_pass = max(1, min(spp, MAX_LANES // lanes_per_spp))
        chunks = [per_pass] * (spp // per_pass) + ([spp % per_pass] if spp % per_pass else [])
        total = None
        for k, n in enumerate(chunks):
            seed = (job["seed"] * 1000003 + k) % (1 << 32)
            img = mi.render(scene, spp=n, seed=seed)
            dr.eval(img)
            dr.sync_thread()
            arr = np.array(img, dtype=np.float64) * n
            total = arr if total is None else total + arr
        return (total / spp).astype(np.float32), len(chunks)

    if not job["variant"].startswith("scalar"):
        # The first render JIT-compiles the kernels; render once at 1 spp so the timed
        # renders below find them in the kernel cache.
        t0 = time.perf_counter()
        render(1)
        out["warmup_seconds"] = time.perf_counter() - t0
    for spp in spps:
        t0 = time.perf_counter()
        img, passes = render(spp)
        seconds = time.perf_counter() - t0
        exr = Path(job["outdir"]) / f"mitsuba-{job['name']}-spp{spp}.exr"
        dr.set_thread_count(io_threads)  # untimed
        mi.Bitmap(img).write(str(exr))
        dr.set_thread_count(job["threads"])
        out["runs"].append({"spp": spp, "seconds": seconds, "passes": passes, "exr": str(exr)})
    Path(job["result"]).write_text(json.dumps(out))


# ---------------------------------------------------------------- parent: running renders


def run_mitsuba(args, variant, spps, outdir):
    """Run the worker for one variant; returns its JSON result or raises Failure."""
    # Files named by variant, and lane count when set (a --keep DIR may hold other runs).
    name = variant
    if args.llvm_lanes and variant.startswith("llvm"):
        name = f"{variant}-{args.llvm_lanes}lanes"
    job = {
        "scene": str(args.scene),
        "variant": variant,
        "name": name,
        "threads": args.threads,
        "llvm_lanes": args.llvm_lanes,
        "seed": args.seed,
        "spps": spps,
        "defines": args.defines,
        "outdir": str(outdir),
        "result": str(outdir / f"mitsuba-{name}.json"),
    }
    Path(job["result"]).unlink(missing_ok=True)  # a --keep DIR may hold an older one
    job_file = outdir / f"job-{name}.json"
    job_file.write_text(json.dumps(job))
    proc = subprocess.run(
        [sys.executable, str(Path(__file__).resolve()), "--_worker", str(job_file)],
        capture_output=True,
        text=True,
    )
    job_file.unlink()
    for line in proc.stderr.splitlines() + proc.stdout.splitlines():
        if " WARN " in line:
            print(f"  mitsuba {variant}: {line.strip()}")
    if proc.returncode != 0 or not Path(job["result"]).exists():
        how = (
            f"was killed by signal {-proc.returncode}"
            if proc.returncode < 0
            else f"exited with code {proc.returncode}"
        )
        text = (proc.stderr + proc.stdout).strip()
        lines = [ln for ln in text.splitlines() if ln.strip()]
        llvm_errors = [ln for ln in lines if ln.startswith("LLVM ERROR")]
        if llvm_errors:
            # LLVM follows its error with a long dump of its selection DAG: leave that out.
            tail = llvm_errors[0][:200] + "\n(LLVM's dump that followed is omitted)"
        else:
            tail = "\n".join(lines[-30:]) if lines else "(no output)"
        msg = f"Mitsuba ({variant}) {how} on {args.scene}:\n{tail}"
        if variant.startswith("llvm") and (
            proc.returncode < 0 or "LLVM" in text or "Cannot select" in text
        ):
            msg += "\nhint: " + LLVM_HINT
        raise Failure(msg)
    return json.loads(Path(job["result"]).read_text())


def run_mltbench(args, spp, outdir):
    """Run `mltbench render`; returns (exr path, samples, seconds, M samples/s, dropped)."""
    exr = outdir / f"mltbench-{args.estimator}-spp{spp}.exr"
    cmd = [
        str(args.mltbench),
        "render",
        str(args.scene),
        "--estimator",
        args.estimator,
        "--spp",
        str(spp),
        "--threads",
        str(args.threads),
        "--seed",
        str(args.seed),
        "-o",
        str(exr),
    ]
    for name, value in args.defines:
        cmd += ["-D", f"{name}={value}"]
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True)
    except OSError as e:
        raise Failure(f"cannot run {args.mltbench}: {e}")
    if proc.returncode != 0:
        raise Failure(
            f"mltbench render failed (exit code {proc.returncode}):\n  {' '.join(cmd)}\n"
            + (proc.stderr.strip() or "(no output on stderr)")
        )
    found = None
    for line in proc.stderr.splitlines():
        m = MLTBENCH_LINE.match(line.strip())
        if m:
            found = m
        elif line.startswith("warning"):
            print(f"  mltbench: {line.strip()}")
    if found is None:
        raise Failure(
            "could not find the report line (`EST: N passes, N samples, T s (X M samples/s, "
            "...`) in mltbench's stderr:\n" + proc.stderr.strip()
        )
    samples = int(found["samples"])
    # The M samples/s figure has more significant digits than the seconds (2 decimals).
    msps = float(found["msps"])
    if msps <= 0:
        msps = samples / max(float(found["secs"]), 1e-9) / 1e6
    dropped = int(found["dropped"]) if found["dropped"] is not None else None
    return exr, samples, float(found["secs"]), msps, dropped


def read_rgb(path):
    """An EXR as a float64 H x W x 3 array (alpha dropped, grey replicated)."""
    import mitsuba as mi
    import numpy as np

    try:
        bmp = mi.Bitmap(str(path))
    except Exception as e:  # Mitsuba raises RuntimeError with a readable message
        raise Failure(f"cannot read {path}: {e}")
    fmt = bmp.pixel_format()
    arr = np.array(bmp, copy=True).astype(np.float64)
    if arr.ndim == 2:
        arr = arr[:, :, None]
    if fmt in (mi.Bitmap.PixelFormat.RGB, mi.Bitmap.PixelFormat.RGBA):
        return arr[:, :, :3]
    if fmt in (mi.Bitmap.PixelFormat.Y, mi.Bitmap.PixelFormat.YA):
        return np.repeat(arr[:, :, :1], 3, axis=2)
    raise Failure(f"{path}: unsupported pixel format {fmt}")


# ---------------------------------------------------------------- parent: statistics


def compare(x, y):
    """x = mltbench image, y = Mitsuba image (the reference of relMSE)."""
    import numpy as np

    npix = x.shape[0] * x.shape[1]
    xs = x.reshape(-1, 3)
    ys = y.reshape(-1, 3)
    mx, my = xs.mean(axis=0), ys.mean(axis=0)
    # Standard error of a channel mean, pixels treated as independent samples: std/sqrt(n).
    # This includes the image's own spatial variation, so it is a generous (large) sigma.
    se_x = xs.std(axis=0, ddof=1) / math.sqrt(npix)
    se_y = ys.std(axis=0, ddof=1) / math.sqrt(npix)
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = mx / my
        # Delta method for a ratio of independent estimates.
        sigma = np.abs(ratio) * np.sqrt((se_x / mx) ** 2 + (se_y / my) ** 2)
        # Paired: the per-pixel difference has zero mean if both images have the same
        # expectation, and its spread is only the two renders' noise (no image structure).
        sigma_paired = (xs - ys).std(axis=0, ddof=1) / math.sqrt(npix) / np.abs(my)
    # docs/DESIGN.md §5: relMSE = mean((x - y)^2 / (y^2 + 0.01)) over pixels and channels.
    relmse = float(np.mean((x - y) ** 2 / (y * y + 0.01)))
    nonfinite = int(np.count_nonzero(~np.isfinite(x))), int(np.count_nonzero(~np.isfinite(y)))
    return {
        "blocks": block_z(x, y),
        "mean_x": mx,
        "mean_y": my,
        "ratio": ratio,
        "sigma": sigma,
        "sigma_paired": sigma_paired,
        "relmse": relmse,
        "nonfinite": nonfinite,
    }


def block_z(x, y, size=16):
    """z-scores of the mean difference over size x size pixel blocks (channels averaged).

    A whole-image mean can hide opposite local errors; per block, the mean difference over
    its standard error is N(0, 1) if the two renderers agree there. Two corrections make
    that true of real images:

    - Neighbouring pixels share samples under a wide reconstruction filter (Mitsuba's
      default Gaussian), so their differences are correlated and std/sqrt(pixels)
      understates the block mean's error. The variance is scaled by the inflation factor
      sum over lags of rho(dx, dy) (1 - |dx|/size) (1 - |dy|/size), with rho the
      difference image's autocorrelation (pixel pairs within blocks) for lags up
      to 4 pixels each way (a filter of radius 2 pixels, Mitsuba's Gaussian, makes pixels
      up to 4 apart share samples): the exact variance of a block mean of a stationary field whose
      correlation vanishes beyond those lags.
    - A block whose pixels do not vary in either image (an environment seen directly, a
      light's face) has a standard error of rounding noise, and any difference between
      the renderers' filtering or float order makes its z explode. Such blocks (standard
      error below 1e-6 of the block's mean value) are left out of the z test and reported
      by their largest relative difference instead.

    Returns None if the image has fewer than 4 blocks, else a dict: blocks (tested), zstd,
    zmax, rect (the pixel rectangle of the largest |z|), inflation, flat (blocks left out)
    and flat_rel (their largest relative difference of means).
    """
    import numpy as np

    nby, nbx = x.shape[0] // size, x.shape[1] // size
    if nby * nbx < 4:
        return None
    h, w = nby * size, nbx * size

    def blocks(img):
        return img.reshape(nby, size, nbx, size).transpose(0, 2, 1, 3)

    d = (x[:h, :w] - y[:h, :w]).mean(axis=2)
    level = blocks(0.5 * (x[:h, :w] + y[:h, :w]).mean(axis=2)).mean(axis=(2, 3))
    db = blocks(d)
    mean = db.mean(axis=(2, 3))
    se = db.reshape(nby, nbx, -1).std(axis=2, ddof=1) / size
    flat = se <= 1e-6 * np.abs(level)
    # Residuals about the mean over tested blocks: removing each block's own mean would
    # bias the correlations low (a block's mean-removed residuals sum to zero).
    inflation = correlation_inflation(db - mean[~flat].mean() if (~flat).any() else db, ~flat, size)
    se = se * math.sqrt(inflation)
    with np.errstate(divide="ignore", invalid="ignore"):
        z = np.where(~flat & (se > 0), mean / se, np.nan)
        rel = np.where(flat & (level != 0), np.abs(mean) / np.abs(level), 0.0)
    ok = np.isfinite(z)
    if ok.sum() < 4:
        return None
    by, bx = np.unravel_index(np.nanargmax(np.abs(z)), z.shape)
    return {
        "blocks": int(ok.sum()),
        "zstd": float(np.nanstd(z)),
        "zmax": float(abs(z[by, bx])),
        "rect": tuple(int(v) for v in (bx * size, by * size, bx * size + size - 1, by * size + size - 1)),
        "inflation": inflation,
        "flat": int(flat.sum()),
        "flat_rel": float(rel.max()) if flat.any() else 0.0,
    }


def correlation_inflation(r, use, size, max_lag=4):
    """Variance inflation of a size x size block mean from the pixels' correlation.

    r: residuals shaped (blocks y, blocks x, size, size), their mean removed;
    use: which blocks to measure on. rho(dx, dy) is averaged over pixel pairs inside the
    same block; negative sums (noise) are clamped to 1, the independent case.
    """
    import numpy as np

    r = r[use]
    if r.shape[0] == 0:
        return 1.0
    var = float(np.mean(r * r))
    if var <= 0:
        return 1.0
    total = 0.0
    for dy in range(-max_lag, max_lag + 1):
        for dx in range(-max_lag, max_lag + 1):
            a = r[:, max(dy, 0) : size + min(dy, 0), max(dx, 0) : size + min(dx, 0)]
            b = r[:, max(-dy, 0) : size + min(-dy, 0), max(-dx, 0) : size + min(-dx, 0)]
            rho = float(np.mean(a * b)) / var
            total += rho * (1 - abs(dx) / size) * (1 - abs(dy) / size)
    return max(total, 1.0)


def self_test():
    """Checks block_z on synthetic images (run with --self-test; needs numpy)."""
    import numpy as np

    rng = np.random.default_rng(1)
    n = 256
    base = np.ones((n, n, 3))
    # Independent pixel noise: z std near 1, inflation near 1.
    x = base + 0.1 * rng.standard_normal((n, n, 3))
    y = base + 0.1 * rng.standard_normal((n, n, 3))
    b = block_z(x, y)
    assert 0.8 < b["zstd"] < 1.2 and b["inflation"] < 1.2, b
    # Pixels correlated as a 5-tap filter makes them: without the inflation z std would be
    # about 1.75-2.5; with it, near 1.
    k = np.array([1, 4, 6, 4, 1], float)
    k /= k.sum()

    def blur(img):
        for axis in (0, 1):
            img = sum(w * np.roll(img, s - 2, axis=axis) for s, w in enumerate(k))
        return img

    x = base + blur(0.3 * rng.standard_normal((n, n, 3)))
    y = base + blur(0.3 * rng.standard_normal((n, n, 3)))
    b = block_z(x, y)
    assert b["inflation"] > 2 and 0.8 < b["zstd"] < 1.25, b
    # A noise-free region (left half) that differs by float rounding only: left out of the
    # z test and reported by its relative difference.
    x = base + 0.1 * rng.standard_normal((n, n, 3))
    y = base + 0.1 * rng.standard_normal((n, n, 3))
    x[:, : n // 2] = 2.0
    y[:, : n // 2] = 2.0 * (1 + 1e-7)
    b = block_z(x, y)
    assert b["flat"] == 128 and b["blocks"] == 128 and b["zstd"] < 1.3, b
    assert b["flat_rel"] < 1e-6, b
    # A real 5% difference in one block is still found.
    x[0:16, 192:208] *= 1.05
    b = block_z(x, y)
    assert b["zmax"] > 5 and b["rect"] == (192, 0, 207, 15), b
    print("crosscheck_mitsuba self-test: ok")


def fit_spp(spps, relmses):
    """Slope of log relMSE vs log spp, and the least-squares fit relMSE = a/spp + b."""
    import numpy as np

    s = np.array(spps, dtype=np.float64)
    r = np.array(relmses, dtype=np.float64)
    ok = r > 0
    slope = float(np.polyfit(np.log(s[ok]), np.log(r[ok]), 1)[0]) if ok.sum() >= 2 else math.nan
    a, b = np.linalg.lstsq(np.stack([1.0 / s, np.ones_like(s)], axis=1), r, rcond=None)[0]
    return slope, float(a), float(b)


# ---------------------------------------------------------------- parent: output


def fmt3(values, spec):
    return "  ".join(format(float(v), spec) for v in values)


def print_block(variant, spp, cmp, mits, mrun, mlt, threads):
    width, height = mits["width"], mits["height"]
    paths = width * height * spp
    mits_mps = paths / mrun["seconds"] / 1e6
    _, mlt_samples, mlt_secs, mlt_mps, dropped = mlt
    print(f"\n== spp {spp}: mltbench vs Mitsuba {variant} ==")
    print(f"{'':22}{'R':>12}{'G':>12}{'B':>12}")
    print(f"{'mean mltbench':22}" + "".join(f"{v:12.6g}" for v in cmp["mean_x"]))
    print(f"{'mean mitsuba':22}" + "".join(f"{v:12.6g}" for v in cmp["mean_y"]))
    print(f"{'ratio mltbench/mits.':22}" + "".join(f"{v:12.5f}" for v in cmp["ratio"]))
    print(f"{'  sigma (std/sqrt n)':22}" + "".join(f"{v:12.5f}" for v in cmp["sigma"]))
    print(f"{'  sigma (paired)':22}" + "".join(f"{v:12.5f}" for v in cmp["sigma_paired"]))
    z = [(r - 1.0) / s if s > 0 else math.nan for r, s in zip(cmp["ratio"], cmp["sigma_paired"])]
    print(f"{'  (ratio-1)/sigma_p':22}" + "".join(f"{v:12.2f}" for v in z))
    if cmp["blocks"] is not None:
        blk = cmp["blocks"]
        n, (x0, y0, x1, y1) = blk["blocks"], blk["rect"]
        # For n independent N(0,1) values the largest |z| is about sqrt(2 ln n).
        print(f"16x16-pixel blocks    z std {blk['zstd']:.2f} over {n} blocks (1 if they agree "
              f"everywhere); largest |z| {blk['zmax']:.1f} (expect ~{math.sqrt(2 * math.log(n)):.1f})"
              f" at pixels x {x0}-{x1}, y {y0}-{y1}")
        print(f"  neighbouring pixels' correlation inflates a block mean's variance "
              f"{blk['inflation']:.2f}x (1 for independent pixels; z is corrected by it)")
        if blk["flat"]:
            print(f"  {blk['flat']} blocks without noise in either image (left out of z): "
                  f"largest relative difference of means {blk['flat_rel']:.2e}")
    print(f"relMSE (y = Mitsuba)  {cmp['relmse']:.6g}")
    if any(cmp["nonfinite"]):
        print(f"  warning: non-finite values: {cmp['nonfinite'][0]} in mltbench, "
              f"{cmp['nonfinite'][1]} in Mitsuba")
    if dropped:
        print(f"  warning: mltbench dropped {dropped} invalid (NaN, infinite or negative) samples")
    print(
        f"throughput mltbench   {mlt_mps:.3f} M paths/s ({mlt_mps / threads:.3f} per thread; "
        f"{mlt_samples} paths in {mlt_secs:.2f} s)"
    )
    print(
        f"throughput mitsuba    {mits_mps:.3f} M paths/s ({mits_mps / threads:.3f} per thread; "
        f"{paths} paths in {mrun['seconds']:.2f} s"
        + (f", {mrun['passes']} launches" if mrun["passes"] > 1 else "")
        + ")"
    )
    print(f"throughput ratio      {mlt_mps / mits_mps:.3f} (mltbench / Mitsuba {variant})")
    return mits_mps, mlt_mps


CSV_FIELDS = [
    "scene", "defines", "estimator", "variant", "spp", "threads", "seed", "width", "height",
    "mean_ratio_r", "mean_ratio_g", "mean_ratio_b",
    "sigma_r", "sigma_g", "sigma_b",
    "sigma_paired_r", "sigma_paired_g", "sigma_paired_b",
    "relmse", "mltbench_mpaths_s", "mitsuba_mpaths_s", "throughput_ratio",
]


def append_csv(path, row):
    path = Path(path)
    new = not path.exists() or path.stat().st_size == 0
    try:
        with path.open("a", newline="") as f:
            w = csv.DictWriter(f, fieldnames=CSV_FIELDS)
            if new:
                w.writeheader()
            w.writerow(row)
    except OSError as e:
        raise Failure(f"cannot write {path}: {e}")


# ---------------------------------------------------------------- parent: main


def parse_args(argv):
    p = argparse.ArgumentParser(
        description="Render a scene with Mitsuba 3 and with mltbench (path tracing) at the "
        "same spp; compare channel means, relMSE and throughput.",
        epilog="See experiments/tools/CROSSCHECK.md.",
    )
    p.add_argument("scene", type=Path, help="Mitsuba 3 XML scene")
    p.add_argument("--spp", type=int, default=64, help="samples per pixel (default 64)")
    p.add_argument(
        "--spp-list",
        metavar="N,N,...",
        help="render at each of these spp and tabulate relMSE against spp (replaces --spp)",
    )
    p.add_argument(
        "--variant",
        default="auto",
        choices=["auto", "scalar_rgb", "llvm_ad_rgb", "both"],
        help="Mitsuba variant (default auto: llvm_ad_rgb if it works, else scalar_rgb)",
    )
    p.add_argument(
        "--mltbench",
        type=Path,
        default=DEFAULT_BINARY,
        help="mltbench binary (default: target/release/mltbench in the repository)",
    )
    p.add_argument("--threads", type=int, default=2, help="threads for both renderers (default 2)")
    p.add_argument("--seed", type=int, default=0, help="seed for both renderers (default 0)")
    p.add_argument(
        "--llvm-lanes",
        type=int,
        choices=[4, 8],
        help="compile llvm_ad_rgb's kernels 4 or 8 lanes wide for AVX2 (default: Dr.Jit's "
        "choice for this CPU, 16 lanes with AVX-512)",
    )
    p.add_argument(
        "-D",
        "--define",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="scene parameter (a <default name=...>) for both renderers, repeatable: "
        "-D res=128 -D max_depth=3",
    )
    p.add_argument("--keep", type=Path, metavar="DIR", help="keep the EXR images in DIR")
    p.add_argument("--csv", type=Path, metavar="FILE", help="append one row per comparison")
    p.add_argument(
        "--estimator",
        default="pt",
        help="mltbench estimator to render with (default pt; lt compares light tracing "
        "against Mitsuba's integrator, which agrees on scenes without specular surfaces "
        "seen by the camera or environment emitters in view)",
    )
    args = p.parse_args(argv)
    if args.spp_list:
        try:
            args.spps = sorted({int(s) for s in args.spp_list.split(",") if s.strip()})
        except ValueError:
            p.error(f"--spp-list: expected comma-separated integers, got {args.spp_list!r}")
    else:
        args.spps = [args.spp]
    if not args.spps or min(args.spps) < 1:
        p.error("spp must be at least 1")
    args.defines = []
    for d in args.define:
        name, eq, value = d.partition("=")
        name = name.strip()
        if not eq or not name:
            p.error(f"-D expects NAME=VALUE, got {d!r}")
        if name == "spp":
            p.error("set the sample count with --spp or --spp-list, not -D spp=")
        args.defines.append((name, value.strip()))
    if args.threads < 1:
        p.error("--threads must be at least 1")
    if args.llvm_lanes and args.variant == "scalar_rgb":
        p.error("--llvm-lanes sets llvm_ad_rgb's kernel width; scalar_rgb has no lanes")
    if not 0 <= args.seed < 1 << 32:
        p.error("--seed must be in [0, 2^32)")
    return args


def check_setup(args):
    try:
        import numpy  # noqa: F401
        import mitsuba as mi
    except ImportError as e:
        raise Failure(
            f"{e.name or 'mitsuba'} is not installed for {sys.executable}. Install Mitsuba 3 "
            f"in a virtual environment and run this script with its Python:\n{VENV_HINT}"
        )
    mi.set_variant("scalar_rgb")  # only for reading EXRs in this process
    if not args.scene.is_file():
        raise Failure(f"scene not found: {args.scene}")
    args.scene = args.scene.resolve()
    if not args.mltbench.is_file():
        raise Failure(
            f"mltbench binary not found at {args.mltbench}: build it with "
            f"`cargo build --release` in {REPO_ROOT}, or pass --mltbench PATH"
        )
    if not os.access(args.mltbench, os.X_OK):
        raise Failure(f"{args.mltbench} is not executable")
    args.mltbench = args.mltbench.resolve()


def main(argv):
    if argv == ["--self-test"]:
        self_test()
        return 0
    if argv[:1] == ["--_worker"] and len(argv) == 2:
        try:
            worker(argv[1])
        except Exception as e:  # the parent shows this message with the variant's name
            print(f"error: {type(e).__name__}: {e}", file=sys.stderr)
            return 2
        return 0
    args = parse_args(argv)
    check_setup(args)
    if args.keep:
        args.keep.mkdir(parents=True, exist_ok=True)
        tmp = None
        outdir = args.keep.resolve()
    else:
        tmp = tempfile.TemporaryDirectory(prefix="crosscheck-")
        outdir = Path(tmp.name)
    try:
        return crosscheck(args, outdir)
    finally:
        if tmp is not None:
            tmp.cleanup()


def crosscheck(args, outdir):
    # Mitsuba first (one child per variant, all spp in it), then mltbench: never concurrently,
    # so the throughputs are measured on an otherwise idle machine.
    results = {}
    if args.variant == "auto" and not args.llvm_lanes:
        try:
            results["llvm_ad_rgb"] = run_mitsuba(args, "llvm_ad_rgb", args.spps, outdir)
        except Failure as e:
            print("note: " + str(e).replace("\n", "\n  "))
            print("note: falling back to scalar_rgb", flush=True)
            results["scalar_rgb"] = run_mitsuba(args, "scalar_rgb", args.spps, outdir)
    else:
        # `auto` with --llvm-lanes: llvm_ad_rgb or a clear failure, never a silent fallback.
        variant = "llvm_ad_rgb" if args.variant == "auto" else args.variant
        variants = ["llvm_ad_rgb", "scalar_rgb"] if variant == "both" else [variant]
        for v in variants:
            results[v] = run_mitsuba(args, v, args.spps, outdir)
    mlt = {spp: run_mltbench(args, spp, outdir) for spp in args.spps}

    any_m = next(iter(results.values()))
    how_spp = "passed as $spp" if any_m["declares_spp"] else "set on render"
    print(f"scene     {args.scene} ({any_m['width']} x {any_m['height']}, "
          f"{any_m['rfilter']}; spp {how_spp})")
    print(f"mltbench  {args.mltbench} --estimator {args.estimator}, "
          f"{args.threads} threads, seed {args.seed}")
    if args.defines:
        print("defines   " + " ".join(f"{n}={v}" for n, v in args.defines) + " (both renderers)")
    for v, m in results.items():
        line = (f"mitsuba   {m['mitsuba']} (drjit {m['drjit']}) {v}, {m['threads']} threads; "
                f"scene load {m['load_seconds']:.2f} s, not timed")
        if m["warmup_seconds"] is not None:
            line += (f"; JIT compilation excluded: a 1-spp warm-up render "
                     f"({m['warmup_seconds']:.2f} s) ran before the timed renders")
        print(line)
    if any_m["rfilter"] != "BoxFilter":
        print(f"note: the film uses {any_m['rfilter']}: neighbouring pixels share samples, so "
              "the sigmas below (pixels taken as independent) are too small")

    tables = {}
    for spp in args.spps:
        x = read_rgb(mlt[spp][0])
        for v, m in results.items():
            mrun = next(r for r in m["runs"] if r["spp"] == spp)
            y = read_rgb(mrun["exr"])
            if x.shape != y.shape:
                raise Failure(f"image sizes differ: mltbench {x.shape[1]} x {x.shape[0]}, "
                              f"Mitsuba {y.shape[1]} x {y.shape[0]}")
            cmp = compare(x, y)
            if args.llvm_lanes and v.startswith("llvm"):
                v = f"{v} ({args.llvm_lanes} lanes)"
            mits_mps, mlt_mps = print_block(v, spp, cmp, m, mrun, mlt[spp], args.threads)
            tables.setdefault(v, []).append((spp, cmp["relmse"]))
            if args.csv:
                row = {
                    "scene": str(args.scene),
                    "defines": ";".join(f"{n}={v}" for n, v in args.defines),
                    "estimator": args.estimator, "variant": v,
                    "spp": spp, "threads": args.threads, "seed": args.seed,
                    "width": m["width"], "height": m["height"],
                    "relmse": f"{cmp['relmse']:.6g}",
                    "mltbench_mpaths_s": f"{mlt_mps:.4f}", "mitsuba_mpaths_s": f"{mits_mps:.4f}",
                    "throughput_ratio": f"{mlt_mps / mits_mps:.4f}",
                }
                for i, c in enumerate("rgb"):
                    row[f"mean_ratio_{c}"] = f"{cmp['ratio'][i]:.6f}"
                    row[f"sigma_{c}"] = f"{cmp['sigma'][i]:.6f}"
                    row[f"sigma_paired_{c}"] = f"{cmp['sigma_paired'][i]:.6f}"
                append_csv(args.csv, row)

    if len(args.spps) > 1:
        for v, rows in tables.items():
            print(f"\n== relMSE against spp (Mitsuba {v}) ==")
            print(f"{'spp':>8}{'relMSE':>14}{'relMSE x spp':>16}")
            for spp, r in rows:
                print(f"{spp:>8}{r:>14.6g}{r * spp:>16.6g}")
            slope, a, b = fit_spp([s for s, _ in rows], [r for _, r in rows])
            print(f"slope of log relMSE vs log spp: {slope:.3f} (-1 when both are unbiased "
                  "and agree)")
            print(f"fit relMSE = a/spp + b: a = {a:.4g}, b = {b:.3g} (b: the part that does "
                  "not fall with spp)")
    if args.keep:
        print(f"\nimages kept in {outdir}")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main(sys.argv[1:]))
    except Failure as e:
        sys.stdout.flush()
        print(f"error: {e}", file=sys.stderr)
        sys.exit(1)
    except KeyboardInterrupt:
        sys.stdout.flush()
        print("interrupted", file=sys.stderr)
        sys.exit(130)
    except BrokenPipeError:  # output piped into `head` and the like
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        sys.exit(1)
