#!/usr/bin/env python3
"""yarnsim against the reference Taichi implementation of Jiang et al. 2017's
yarn bundle, side by side.

Usage (normally through tools/bench/taichi_bench.sh, which sets up Taichi 1.7.4):

    python tools/bench/taichi_bench.py REFERENCE_FILE [--yarnsim BIN] [--threads 1,2]
        [--rounds 3] [--steps 1000] [--warmup 100] [--f64]

REFERENCE_FILE is `aempm/aempm_2d_pill.py` of
github.com/zzigak/Anisotropic-Elastoplastic-model-in-MPM at commit 3cc3af6
(not shipped with yarnsim: it carries no licence; see the README).

For every round and thread count J the script runs `yarnsim bench
yarn-reference -j J --steps N --warmup W` and, in a fresh process, the
reference implementation's substep (its seven kernels, in the order of its
`main()` loop) on the CPU with `ti.init(arch=ti.cpu, cpu_max_num_threads=J)`, no GUI: W
untimed substeps (they include Taichi's kernel compilation), then N timed
ones ending with `ti.sync()`. The order of the two programs alternates from
round to round. Throughput is particle-substeps/s with the same particle
count for both: vertices + quadrature particles (12 x 200 + 12 x 199 =
4788). The reference implementation's scene is moved onto yarnsim's
reference scene (yarn start, length and spacing; the rest already agrees);
the remaining differences in the physics are listed in the README.

Internal: `--worker` runs one Taichi measurement and prints
`<number> particle-substeps/s`.
"""

import argparse
import hashlib
import importlib.util
import os
import statistics
import subprocess
import sys
import time

REFERENCE_SHA256 = "ba1c22e8c424912bf16b27d48d69507ded0d5b07b71d4d3de004e76365839579"
RATE_SUFFIX = " particle-substeps/s"

# yarnsim's `yarn-reference` (src/scene/builtin.rs) against the reference file's
# module constants: (name, reference value, yarnsim value).
SCENE_PATCH = [
    ("start_pos", (0.2, 0.8), (0.1, 0.75)),  # first vertex of the first yarn
    ("Length", 0.75, 0.8),  # yarn length
    ("dlx", 0.015, 0.01),  # spacing between the yarns (y)
]
# Already equal in both: 12 yarns x 200 vertices, 256^2 grid over 1 m,
# dt 4e-5, density 1, k 1000, gamma 500, E 1000, return-mapping friction
# 0.05, gravity 9.8, three circles of radius 0.08 at (0.25, 0.6),
# (0.5, 0.3), (0.75, 0.5), attractor off, walls 3 cells.
REFERENCE_EQUAL = [
    ("N_Line", 12),
    ("ln_type2", 200),
    ("n_grid", 256),
    ("dt", 4e-5),
    ("p_rho", 1),
    ("k", 1000),
    ("gamma", 500),
    ("E", 1000),
    ("cf", 0.05),
    ("bound", 3),
    ("Circle1_Radius", 0.08),
    ("Circle2_Radius", 0.08),
    ("Circle3_Radius", 0.08),
]


def worker(args):
    import taichi as ti

    real_init = ti.init

    def cpu_init(*_a, **_kw):  # the reference program calls ti.init(arch=ti.gpu) on import
        return real_init(
            arch=ti.cpu,
            cpu_max_num_threads=args.threads,
            default_fp=ti.f64 if args.f64 else ti.f32,
            log_level=ti.WARN,
        )

    ti.init = cpu_init
    try:
        spec = importlib.util.spec_from_file_location("aempm_reference", args.reference)
        ref = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(ref)  # not __main__: main() (the GUI loop) does not run
    finally:
        ti.init = real_init

    for name, want in REFERENCE_EQUAL:
        got = getattr(ref, name)
        if abs(got - want) > 1e-12 * abs(want):
            sys.exit(f"reference file: {name} = {got}, expected {want} (not the 3cc3af6 version?)")
    for name, ref_value, ours in SCENE_PATCH:
        got = getattr(ref, name)
        got = tuple(got) if name == "start_pos" else got
        if got != ref_value:
            sys.exit(f"reference file: {name} = {got}, expected {ref_value} (not the 3cc3af6 version?)")
    # Kernels read module globals when they are first compiled (below), so
    # setting them now moves the scene. volume2/3 and sl follow from Length.
    ref.start_pos = ti.Vector(list(SCENE_PATCH[0][2]))
    ref.Length = SCENE_PATCH[1][2]
    ref.dlx = SCENE_PATCH[2][2]
    ref.sl = ref.Length / (ref.ln_type2 - 1)
    ref.volume2 = ref.dx * ref.Length / (ref.ln_type3 + ref.ln_type2)
    ref.volume3 = ref.volume2
    ref.attractor_strength[None] = 0.0  # the GUI loop sets 0 unless a mouse button is down

    particles = ref.n_type2 + ref.n_type3
    kernels = [
        ref.Reset,
        ref.Particle_To_Grid,
        ref.Grid_Force,
        ref.Grid_Collision,
        ref.Grid_To_Particle,
        ref.Update_Particle_State,
        ref.Return_Mapping,
    ]

    def substeps(n):
        for _ in range(n):
            for kernel in kernels:
                kernel()

    ref.initialize()
    substeps(args.warmup)
    ti.sync()
    t0 = time.perf_counter()
    substeps(args.steps)
    ti.sync()
    seconds = time.perf_counter() - t0

    x = ref.x2.to_numpy()
    if not (x == x).all():
        sys.exit("reference run: non-finite vertex positions")
    fp = "f64" if args.f64 else "f32"
    print(
        f"taichi reference: {particles} particles, {args.steps} substeps after {args.warmup} warm-up, "
        f"{args.threads} thread(s), {fp}, {seconds:.3f} s, vertices x {x[:, 0].min():.4f}..{x[:, 0].max():.4f}, "
        f"mean y {x[:, 1].mean():.6f}"
    )
    print(f"{particles * args.steps / seconds:.0f}{RATE_SUFFIX}")


def rate_of(output, what):
    for line in output.splitlines():
        if line.endswith(RATE_SUFFIX):
            return float(line[: -len(RATE_SUFFIX)])
    sys.exit(f"{what}: no '<number>{RATE_SUFFIX}' line in its output:\n{output}")


def run(cmd, what):
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        sys.exit(f"{what} failed ({p.returncode}): {' '.join(cmd)}\n{p.stdout}{p.stderr}")
    return rate_of(p.stdout, what)


def mega(r):
    return f"{r / 1e6:.2f} M"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("reference", help="path of aempm/aempm_2d_pill.py (commit 3cc3af6)")
    ap.add_argument("--yarnsim", default=None, help="yarnsim binary (default: target/release/yarnsim)")
    ap.add_argument("--threads", default="1,2", help="comma-separated thread counts (default 1,2)")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--steps", type=int, default=1000, help="timed substeps (yarnsim bench default)")
    ap.add_argument("--warmup", type=int, default=100, help="untimed substeps (yarnsim bench default)")
    ap.add_argument("--f64", action="store_true", help="run the reference in f64 (it is written for Taichi's default f32)")
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()

    if args.worker:
        args.threads = int(args.threads)
        worker(args)
        return

    reference = os.path.abspath(args.reference)
    with open(reference, "rb") as f:
        digest = hashlib.sha256(f.read()).hexdigest()
    if digest != REFERENCE_SHA256:
        print(f"warning: {reference} is not the 3cc3af6 version (sha256 {digest})")
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    yarnsim = args.yarnsim or os.path.join(root, "target", "release", "yarnsim")
    if not os.access(yarnsim, os.X_OK):
        sys.exit(f"no yarnsim binary at {yarnsim}: cargo build --release -p yarnsim-cli, or pass --yarnsim")
    threads = [int(t) for t in args.threads.split(",")]

    import taichi

    print(
        f"yarnsim {yarnsim} against the reference {reference} on Taichi {'.'.join(map(str, taichi.__version__))} "
        f"(CPU, {'f64' if args.f64 else 'f32'}), scene yarn-reference, 4788 particles, "
        f"{args.steps} timed substeps after {args.warmup} warm-up, {args.rounds} rounds, alternating"
    )
    results = {j: [] for j in threads}  # j -> [(yarnsim, taichi)]
    for r in range(args.rounds):
        for j in threads:
            ycmd = [yarnsim, "bench", "yarn-reference", "-j", str(j),
                    "--steps", str(args.steps), "--warmup", str(args.warmup)]
            tcmd = [sys.executable, os.path.abspath(__file__), reference, "--worker", "--threads", str(j),
                    "--steps", str(args.steps), "--warmup", str(args.warmup)] + (["--f64"] if args.f64 else [])
            if r % 2 == 0:
                y = run(ycmd, "yarnsim")
                t = run(tcmd, "taichi reference")
            else:
                t = run(tcmd, "taichi reference")
                y = run(ycmd, "yarnsim")
            results[j].append((y, t))
            first = "yarnsim first" if r % 2 == 0 else "taichi first"
            print(f"round {r + 1}, {j} thread(s) ({first}): yarnsim {mega(y)}, taichi {mega(t)} "
                  f"particle-substeps/s, ratio {y / t:.1f}x", flush=True)

    print()
    print("| threads | yarnsim (median) | taichi reference (median) | ratio of medians | ratio per round |")
    print("|---|---|---|---|---|")
    for j in threads:
        ys = [y for y, _ in results[j]]
        ts = [t for _, t in results[j]]
        ym, tm = statistics.median(ys), statistics.median(ts)
        per = ", ".join(f"{y / t:.1f}x" for y, t in results[j])
        print(f"| {j} | {mega(ym)} | {mega(tm)} | {ym / tm:.1f}x | {per} |")
    print("(particle-substeps/s; M = 10^6)")


if __name__ == "__main__":
    main()
