"""Mitsuba 3's ray-casting rate on a scene, for comparison with `cargo bench --bench rays`.

Casts the same kind of incoherent rays as the bench's `flat_crossover` group: origins uniform
in the scene's bounding box, directions uniform on the sphere. Times, per query, the best of
four calls:

- `closest`: `ray_intersect_preliminary` (distance and primitive only: mltbench's kernel
  query `closest_hit`);
- `closest+surface`: `ray_intersect` with position, normals and uv evaluated (mltbench's
  `intersect`);
- `shadow`: `ray_test` on segments ending halfway to each ray's closest hit (unbounded for
  rays that escape), as the bench's any-hit case.

    /work/venv-mitsuba/bin/python experiments/tools/mitsuba_ray_rate.py \\
        experiments/scenes/cbox.xml [--threads 1] [--rays 4194304] [--variant llvm_ad_rgb]

Setting up Mitsuba: CROSSCHECK.md beside this file.
"""

import argparse
import sys
import time


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("scene", help="Mitsuba 3 XML scene")
    parser.add_argument("--threads", type=int, default=1, help="Dr.Jit threads (default 1)")
    parser.add_argument("--rays", type=int, default=1 << 22, help="rays per call")
    parser.add_argument(
        "--variant",
        default="llvm_ad_rgb",
        choices=["llvm_ad_rgb", "llvm_rgb"],
        help="a vectorised variant (rays are cast as one wavefront)",
    )
    args = parser.parse_args()
    if args.threads < 1 or args.rays < 1:
        parser.error("--threads and --rays must be positive")
    try:
        import drjit as dr
        import mitsuba as mi
    except ImportError as e:
        sys.exit(f"mitsuba_ray_rate: {e}; see experiments/tools/CROSSCHECK.md")
    try:
        mi.set_variant(args.variant)
    except Exception as e:  # noqa: BLE001 (Mitsuba raises plain exceptions)
        sys.exit(f"mitsuba_ray_rate: variant {args.variant} unavailable: {e}")
    dr.set_thread_count(args.threads)
    try:
        scene = mi.load_file(args.scene)
    except Exception as e:  # noqa: BLE001
        sys.exit(f"mitsuba_ray_rate: {args.scene}: {e}")

    n = args.rays
    rng = mi.PCG32(size=n)
    lo, hi = scene.bbox().min, scene.bbox().max
    o = mi.Point3f(
        lo.x + (hi.x - lo.x) * rng.next_float32(),
        lo.y + (hi.y - lo.y) * rng.next_float32(),
        lo.z + (hi.z - lo.z) * rng.next_float32(),
    )
    d = mi.warp.square_to_uniform_sphere(mi.Point2f(rng.next_float32(), rng.next_float32()))
    rays = mi.Ray3f(o, d)
    first = scene.ray_intersect_preliminary(rays)
    half = mi.Ray3f(o, d)
    half.maxt = dr.select(first.is_valid(), 0.5 * first.t, dr.inf)
    dr.eval(rays, half)

    def closest():
        r = scene.ray_intersect_preliminary(rays)
        dr.eval(r.t, r.prim_index)

    def closest_surface():
        r = scene.ray_intersect(rays)
        dr.eval(r.t, r.p, r.n, r.sh_frame.n, r.uv)

    def shadow():
        dr.eval(scene.ray_test(half))

    print(f"{args.scene}: {n} rays, {mi.variant()}, {args.threads} thread(s)")
    for name, query in [
        ("closest", closest),
        ("closest+surface", closest_surface),
        ("shadow", shadow),
    ]:
        best = float("inf")
        for _ in range(4):
            dr.sync_thread()
            t0 = time.perf_counter()
            query()
            dr.sync_thread()
            best = min(best, time.perf_counter() - t0)
        print(f"{name:16s} {n / best / 1e6:7.2f} M rays/s")


if __name__ == "__main__":
    main()
