#!/usr/bin/env python3
"""Side-by-side rod benchmark: yarnsim against MuJoCo 4.0.0 and PyElastica
1.0.0 on the oracle scenes of yarnsim's tests (hanging chain, cantilever,
heavy-rope capstan) and the reference bundle.

    bash tools/bench/peers/setup.sh && tools/bench/peers/.venv/bin/python tools/bench/peers/bench.py
        [--quick] [--rounds 3] [--out docs/performance] [--skip-bundle]

Every run is one thread (NUMBA_NUM_THREADS, OMP_NUM_THREADS and
RAYON_NUM_THREADS are set to 1 before the peers are imported; one bundle
row of yarnsim on 2 threads says so) and times its stepping loop only.
The timed cases run in `--rounds` rounds; within a round the tools take turns (the order rotates from round to round) and the
wall time is the median over the rounds; errors are deterministic. The
capstan threshold is a bisection (slides at 0.7 mu*, holds at 1.4 mu*, then
five halvings: a bracket of 2.2 % of mu*; yarnsim's test does three) and
runs once. The bundle runs the scene's whole second (`--bundle-duration`),
timed in two windows (the fall and landing to 0.2 s, then the drape); its
cheap runs alternate over the rounds, the slow ones (grid implicit, MuJoCo
at CG tolerance 1e-16 and with deleted joints) run once. yarnsim runs on
the grid under both integrators (`mpm-explicit`,
`mpm-implicit`) and, for the single-yarn oracles, on the vertices without
the grid (`vertices-implicit`, `vertices-midpoint`);
a scene the implicit integrator refuses is a row with ok=False and the
refusal in `note`. `--quick` (under a minute) runs the coarsest chain and
cantilever of each tool (and the implicit chain at 25 vertices, dt 1e-2), once, and writes `peers_quick.csv` / `.svg` into `--out` (default
for quick: the system temp directory) instead of `peers.csv` / `.svg`.
`--only nylon,bundle-preset,bundle-converged,bundle-ladder` runs only
the real-yarn cases (the nylon monofilament's hanging chain and capstan
in every tool, the bundle with a preset in yarnsim and MuJoCo, the bundle
at yarnsim's converged setting against MuJoCo at two steps, the bundle
with a preset at a ladder of steps in each tool; README, "Real yarns")
and replaces their rows in the existing CSV.
"""

import argparse
import csv
import math
import os
import statistics
import sys
import tempfile
import time

for _v in ("NUMBA_NUM_THREADS", "OMP_NUM_THREADS", "RAYON_NUM_THREADS", "OPENBLAS_NUM_THREADS"):
    os.environ[_v] = "1"
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import numpy as np  # noqa: E402

import bundle_metrics  # noqa: E402
import elastica_rope  # noqa: E402
import mujoco_rope  # noqa: E402
import oracles as O  # noqa: E402
import plot  # noqa: E402
import yarnsim_rope  # noqa: E402

ROOT = yarnsim_rope.ROOT


def cases(quick):
    """(tool, integrator, case, setting, callable) of the timed cases."""
    c = []
    ch_mj = [(25, 1e-2)] if quick else [(25, 1e-2), (50, 5e-3), (99, 2e-3)]
    ch_el = [25] if quick else [25, 50]
    ch_ys = [(25, 16, '"auto"')] if quick else [(25, 16, '"auto"'), (50, 32, '"auto"'),
                                                (100, 64, "1e-4")]
    for n, dt in ch_mj:
        c.append(("mujoco", "discrete", "chain", f"{n} elements, dt {dt:g}",
                  lambda n=n, dt=dt: mujoco_rope.chain(n, dt)))
    for n in ch_el:
        dt = 1.4e-4 * 25 / n
        c.append(("pyelastica", "position-verlet", "chain", f"{n} elements, dt {dt:.3g}",
                  lambda n=n: elastica_rope.chain(n)))
    for v, g, dt in ch_ys:
        c.append(("yarnsim", "mpm-explicit", "chain",
                  f"{v} vertices, {g}^2, dt {dt.strip(chr(34))}",
                  lambda v=v, g=g, dt=dt: yarnsim_rope.chain(v, g, dt)))
    # backward Euler (`integrator = "implicit"`): 10x and 100x the explicit
    # step, and dt "auto" (the advection limit capped by dt_max = frame_dt);
    # with k = 2e5 the yarn is nearly inextensible, as MuJoCo's rope is
    # (its stretch bias 0.001 % instead of +0.11..0.16 %)
    ch_im = [(25, 16)] if quick else [(25, 16), (50, 32), (100, 64)]
    dts_im = ["1e-2"] if quick else ["1e-3", "1e-2", '"auto"']
    for v, g in ch_im:
        for dt in dts_im:
            c.append(("yarnsim", "mpm-implicit", "chain",
                      f"{v} vertices, {g}^2, dt {dt.strip(chr(34))}",
                      lambda v=v, g=g, dt=dt: yarnsim_rope.chain(v, g, dt, "implicit")))
    for v, g in ch_im:
        for dt in ["2e-3"] if quick else ["1e-3", "2e-3", "5e-3", "1e-2"]:
            c.append(("yarnsim", "mpm-implicit-k2e5", "chain",
                      f"{v} vertices, {g}^2, dt {dt}, k 2e5",
                      lambda v=v, g=g, dt=dt: yarnsim_rope.chain(v, g, dt, "implicit", 2e5)))
    # without the grid: one yarn's vertices by backward Euler
    # (`integrator = "implicit-vertices"`) and the generalized midpoint rule
    # (`"midpoint-vertices"`, theta 0.55), k = 2e5 as above
    ch_gl = [(50, "1e-2")] if quick else [(25, "1e-2"), (40, "1e-2"), (50, "1e-2"), (50, "5e-3"),
                                         (100, "5e-3"), (100, "2e-3"), (150, "2e-3")]
    for integ, name in [("midpoint-vertices", "vertices-midpoint"),
                        ("implicit-vertices", "vertices-implicit")]:
        for v, dt in ch_gl:
            c.append(("yarnsim", name, "chain", f"{v} vertices, no grid, dt {dt}, k 2e5",
                      lambda v=v, dt=dt, integ=integ: yarnsim_rope.chain(v, 16, dt, integ, 2e5)))
    ca_mj = [25] if quick else [25, 50, 100]
    ca_el = [] if quick else [25, 50]
    ca_ys = [] if quick else [100, 200]
    for n in ca_mj:
        c.append(("mujoco", "discrete", "cantilever", f"{n} elements, dt 1e-3",
                  lambda n=n: mujoco_rope.cantilever(n, 1e-3)))
    for n in ca_el:
        c.append(("pyelastica", "position-verlet", "cantilever", f"{n} elements",
                  lambda n=n: elastica_rope.cantilever(n)))
    for v in ca_ys:
        c.append(("yarnsim", "mpm-explicit", "cantilever", f"{v} vertices, 64^2, dt 5e-5",
                  lambda v=v: yarnsim_rope.cantilever(v)))
    # the same scenes under the implicit integrator at 20x and 40x the
    # explicit step
    for v in ca_ys:
        for dt in (1e-3, 2e-3):
            c.append(("yarnsim", "mpm-implicit", "cantilever", f"{v} vertices, 64^2, dt {dt:g}",
                      lambda v=v, dt=dt: yarnsim_rope.cantilever(v, "implicit", dt)))
    for v, dts in [] if quick else [(25, (5e-4, 1e-3, 2e-3)), (50, (2.5e-4, 1e-3, 2e-3))]:
        for dt in dts:
            c.append(("yarnsim", "vertices-midpoint", "cantilever",
                      f"{v} vertices, no grid, dt {dt:g}",
                      lambda v=v, dt=dt: yarnsim_rope.cantilever(v, "midpoint-vertices", dt)))
    return c


def interleave(cs, rounds):
    """Runs every case `rounds` times, the tools taking turns within a
    round (order rotated by round); returns {index: [results]}."""
    tools = sorted({t for t, *_ in cs})
    by_tool = {t: [i for i, x in enumerate(cs) if x[0] == t] for t in tools}
    results = {i: [] for i in range(len(cs))}
    for r in range(rounds):
        order = tools[r % len(tools):] + tools[:r % len(tools)]
        queues = {t: list(by_tool[t]) for t in order}
        while any(queues.values()):
            for t in order:
                if queues[t]:
                    i = queues[t].pop(0)
                    res = cs[i][4]()
                    results[i].append(res)
                    if "refused" in res:
                        print(f"  round {r + 1} {cs[i][0]:10s} {cs[i][1]:12s} {cs[i][2]:10s} "
                              f"{cs[i][3]:28s} refused: {res['refused']}", flush=True)
                        continue
                    print(f"  round {r + 1} {cs[i][0]:10s} {cs[i][1]:12s} {cs[i][2]:10s} "
                          f"{cs[i][3]:28s} error {res['error']:+.4%} wall {res['wall_s']:.3f} s "
                          f"for {res['sim_s']:.3f} s", flush=True)
    return results


def capstan(tool, slides, setting, integrator, rows, case="capstan", c=None, rope_radius=None):
    """Bisection of the slip threshold between 0.7 and 1.4 mu* with
    `slides(mu) -> (slid, wall, sim)`; one row. `c`: the capstan
    (`O.CAPSTAN` or `O.capstan_scaled`); `rope_radius` (m): how far the
    rope's centreline lies from the drum (default: MuJoCo's 1 mm,
    PyElastica's 2 mm; yarnsim's yarn has no radius)."""
    c = c or O.CAPSTAN
    if rope_radius is None:
        rope_radius = {"mujoco": 1e-3, "pyelastica": 2e-3}.get(tool, 0.0)
    r_eff = c["radius"] + rope_radius
    mu_star = O.capstan_threshold(r_eff, c["l1"], c["l2"])
    wall = sim = 0.0
    ok = True

    def run(mu):
        nonlocal wall, sim
        s, w, t = slides(mu)
        wall += w
        sim += t
        return s

    lo, hi = 0.7 * mu_star, 1.4 * mu_star
    try:
        if not run(lo) or run(hi):
            ok = False
        else:
            for _ in range(5):
                mid = 0.5 * (lo + hi)
                if run(mid):
                    lo = mid
                else:
                    hi = mid
    except yarnsim_rope.Refused as e:
        print(f"  capstan {tool:10s} {integrator} {setting}: refused: {e}", flush=True)
        rows.append(refused_row(tool, integrator, case, setting, str(e)))
        return
    mu = 0.5 * (lo + hi)
    err = (mu - mu_star) / mu_star
    print(f"  capstan {tool:10s} {setting}: mu* {mu_star:.4f}, threshold in [{lo:.4f}, {hi:.4f}], "
          f"error {err:+.2%} (bracket [{(lo - mu_star) / mu_star:+.1%}, "
          f"{(hi - mu_star) / mu_star:+.1%}]), {wall:.2f} s wall for {sim:.2f} s", flush=True)
    rows.append(dict(tool=tool, integrator=integrator, case=case, setting=setting,
                     error=err if ok else float("nan"), wall_s_per_sim_s=wall / sim,
                     wall_s=wall, sim_s=sim, rounds=1, ok=ok,
                     note=f"mu* {mu_star:.4f}, bracket [{(lo - mu_star) / mu_star:+.1%}, "
                          f"{(hi - mu_star) / mu_star:+.1%}]"))


def refused_row(tool, integrator, case, setting, note):
    """A run the scene validation refused: ok=False, the refusal in note."""
    nan = float("nan")
    return dict(tool=tool, integrator=integrator, case=case, setting=setting, error=nan,
                wall_s_per_sim_s=nan, wall_s=nan, sim_s=nan, rounds=1, ok=False, note=note)


def _windows(res):
    """Wall seconds per simulated second in each timed window of a bundle
    run, as text: the fall and landing, then the draped rest."""
    return "; ".join(f"{a:g}-{b:.2g} s: {w / (b - a):.3g} s/s" for a, b, w in res["windows"]
                     if b > a)


def bundle(rows, duration, implicit_duration, rounds):
    """The reference bundle over `duration` s (the built-in scene's whole
    second by default), timed in two windows (to 0.2 s: the fall and
    landing; then the drape). The cheap runs go in `rounds` alternating
    rounds (order rotated by round; median wall time, the window times of
    the median run); the grid implicit step (about 500 s/s, over
    `implicit_duration` s only), MuJoCo with a tight CG tolerance (about
    50 s/s) and MuJoCo with deleted joints (a minute to compile, about
    130 s/s) run once."""
    b = O.BUNDLE
    runs = [
        ("yarnsim", "mpm-explicit", "256^2, dt auto (yarn-reference)", True,
         lambda: yarnsim_rope.bundle(duration, "explicit", "auto")),
        ("mujoco", "discrete", "CG, dt 1e-3, r 1.9 mm, planar (y armature 1e6)", True,
         lambda: mujoco_rope.bundle(duration, planar="armature")),
        ("yarnsim", "mpm-explicit", "256^2, dt 4e-5 (yarn-reference)", True,
         lambda: yarnsim_rope.bundle(duration)),
        ("yarnsim", "mpm-explicit", "256^2, dt auto, 2 threads", True,
         lambda: yarnsim_rope.bundle(duration, "explicit", "auto", threads=2)),
        ("yarnsim", "mpm-implicit", f"256^2, dt 1e-3, first {implicit_duration:g} s", False,
         lambda: yarnsim_rope.bundle(implicit_duration, "implicit", 1e-3)),
        # the armature raises the inertia that scales MuJoCo's CG stopping
        # test: the run above stops after ~20 iterations per step once the
        # bundle has landed; at tolerance 1e-16 it runs to the cap (100) as
        # the deleted-joint run does
        ("mujoco", "discrete", "CG tolerance 1e-16, dt 1e-3, r 1.9 mm, planar (y armature 1e6)",
         False, lambda: mujoco_rope.bundle(duration, planar="armature", tolerance=1e-16)),
        ("mujoco", "discrete", "CG, dt 1e-3, r 1.9 mm, planar (y joints deleted)", False,
         lambda: mujoco_rope.bundle(duration, planar="delete")),
    ]
    results = {i: [] for i in range(len(runs))}
    for r in range(rounds):
        order = list(range(len(runs)))
        order = order[r % len(order):] + order[:r % len(order)]
        for i in order:
            tool, integ, setting, repeat, fn = runs[i]
            if r > 0 and not repeat:
                continue
            res = fn()
            results[i].append(res)
            if "refused" in res:
                print(f"  bundle {tool:10s} {integ} {setting}: refused: {res['refused']}",
                      flush=True)
                continue
            print(f"  round {r + 1} bundle {tool:10s} {setting}: {res['wall_s']:.2f} s wall for "
                  f"{res['sim_s']:.3f} s; {_windows(res)}", flush=True)
    for i, (tool, integ, setting, _, _) in enumerate(runs):
        rs = results[i]
        if "refused" in rs[0]:
            rows.append(refused_row(tool, integ, "bundle", setting, rs[0]["refused"]))
            continue
        res = sorted(rs, key=lambda x: x["wall_s"])[len(rs) // 2]  # the median run
        m = _windows(res) + "; " + bundle_metrics.describe(res["yarns"], b)
        if "out_of_plane" in res:
            m += f"; out-of-plane drift {res['out_of_plane']:.2e} m"
        if res.get("passes") and res.get("steps"):
            total = sum(t for _, t in res["passes"])
            parts = ", ".join(f"{name.split(' + ')[0].split(' (')[0]} {100 * t / total:.0f} %"
                              for name, t in res["passes"] if t > 0 and not
                              name.startswith("stress refresh"))
            m += (f"; {res['steps']} substeps (mean dt {res['sim_s'] / res['steps']:.3g} s), "
                  f"{1e3 * res['wall_s'] / res['steps']:.3g} ms each: {parts}")
        if "solver_iterations" in res:
            m += "; CG iterations per step (cap {}): {}".format(res["iteration_cap"], ", ".join(
                f"{a:g}-{b:.2g} s {it:.1f} ({100 * cap:.0f} % of steps at the cap, "
                f"{con:.0f} contacts)" for (a, b, _), it, cap, con in
                zip(res["windows"], res["solver_iterations"], res["at_cap"], res["contacts"])))
        print(f"  bundle {tool:10s} {setting}: median {res['wall_s']:.2f} s wall for "
              f"{res['sim_s']:.3f} s over {len(rs)} round(s); {m}", flush=True)
        rows.append(dict(tool=tool, integrator=integ, case="bundle", setting=setting,
                         error=float("nan"), wall_s_per_sim_s=res["wall_s"] / res["sim_s"],
                         wall_s=res["wall_s"], sim_s=res["sim_s"], rounds=len(rs),
                         ok=all(x["ok"] for x in rs), note=m))
    rows.append(dict(tool="pyelastica", integrator="position-verlet", case="bundle",
                     setting="not run", error=float("nan"), wall_s_per_sim_s=float("nan"),
                     wall_s=float("nan"), sim_s=float("nan"), rounds=0, ok=False,
                     note="RodRodContact has no friction (normal spring-dashpot only); "
                          "see README"))


def _bundle_row(case, tool, integ, setting, rs, extra=""):
    """One bundle row from the runs `rs` of one set-up (the median by wall
    time, its windows and what the bundle did at the end)."""
    res = sorted(rs, key=lambda x: x["wall_s"])[len(rs) // 2]
    note = _windows(res) + "; " + bundle_metrics.describe(res["yarns"], O.BUNDLE)
    if "out_of_plane" in res:
        note += f"; out-of-plane drift {res['out_of_plane']:.2e} m"
    if res.get("steps"):
        note += f"; {res['steps']} substeps (mean dt {res['sim_s'] / res['steps']:.3g} s)"
    if "solver_iterations" in res:
        note += "; CG iterations per step: " + ", ".join(
            f"{a:g}-{b:.2g} s {it:.1f}" for (a, b, _), it in
            zip(res["windows"], res["solver_iterations"]))
    note += extra
    print(f"  {case} {tool:10s} {setting}: median {res['wall_s']:.2f} s wall for "
          f"{res['sim_s']:.3f} s over {len(rs)} round(s); {note}", flush=True)
    return res, dict(tool=tool, integrator=integ, case=case, setting=setting, error=float("nan"),
                     wall_s_per_sim_s=res["wall_s"] / res["sim_s"], wall_s=res["wall_s"],
                     sim_s=res["sim_s"], rounds=len(rs), ok=all(x["ok"] for x in rs), note=note)


def _distances(a, b):
    """Text: how far the frames of two bundle runs lie apart."""
    d = bundle_metrics.frame_distances(a["frames"], b["frames"])
    if d is None:
        return "no common frames"
    return (f"centre of mass {100 * d['com_end']:.2f} cm apart at the end, at most "
            f"{100 * d['com_max']:.2f} cm; ends {100 * d['ends_end']:.1f} cm at the end, at most "
            f"{100 * d['ends_max']:.1f} cm ({d['frames']} frames, every 0.1 s)")


NYLON = "nylon66-mono-0.30mm"


def nylon(rows, rounds):
    """The hanging chain as one real yarn of the nylon monofilament preset
    in every tool (its EA, EI and tex), against the hanging rod's period
    (`oracles.hanging_beam_period`: the bending shortens the string's by
    0.15 %), the tools taking turns over `rounds` rounds. PyElastica's
    step is the shear-rotation bound, not the axial one: at the chain's
    5 mm radius the rotational inertia mu r^2 / 4 of the light yarn needs
    dt 5e-6 (1e-5 oscillates), below 0.7 l / c = 1.5e-5."""
    mat = O.preset_chain(NYLON)
    c = []
    for n, dt in [(25, 1e-2), (50, 5e-3), (99, 2e-3)]:
        c.append(("mujoco", "discrete", "chain-nylon", f"{n} elements, dt {dt:g}",
                  lambda n=n, dt=dt: mujoco_rope.chain(n, dt, material=mat)))
    c.append(("pyelastica", "position-verlet", "chain-nylon", "25 elements, dt 5e-6, r 5 mm",
              lambda: elastica_rope.chain(25, dt=5e-6, material=mat)))
    for v, g in [(25, 16), (50, 32), (100, 64)]:
        c.append(("yarnsim", "mpm-axial-implicit", "chain-nylon",
                  f"{v} vertices, {g}^2, APIC, axial implicit, dt auto",
                  lambda v=v, g=g: yarnsim_rope.chain_preset(NYLON, v, g, '"auto"',
                                                             mat["oracle"])))
    # one yarn needs no grid: its vertices under the midpoint rule (the
    # preset's EA, EI and mass; `peers_chain chain-preset ... INTEGRATOR`),
    # at the settings that reach MuJoCo's three errors
    for v, dt in [(40, 1e-2), (100, 5e-3), (100, 2e-3), (150, 2e-3)]:
        c.append(("yarnsim", "vertices-midpoint", "chain-nylon",
                  f"{v} vertices, no grid, dt {dt:g}",
                  lambda v=v, dt=dt: yarnsim_rope.chain_preset(NYLON, v, 16, dt, mat["oracle"],
                                                               "midpoint-vertices")))
    res = interleave(c, rounds)
    for i, (tool, integ, case, setting, _) in enumerate(c):
        rs = res[i]
        wall = statistics.median(r["wall_s"] for r in rs)
        sim = rs[0]["sim_s"]
        note = f"oracle {mat['oracle']:.6f} s (hanging rod, EI {mat['bending']:g} N m^2)"
        if "steps" in rs[0]:
            note += f"; {rs[0]['steps']} substeps"
        rows.append(dict(tool=tool, integrator=integ, case=case, setting=setting,
                         error=rs[0]["error"], wall_s_per_sim_s=wall / sim, wall_s=wall,
                         sim_s=sim, rounds=len(rs), ok=all(r["ok"] for r in rs), note=note))


# The nylon capstan's lengths against `O.CAPSTAN`: on the 0.1 m drum the
# monofilament's bending moment EI / R (9.9e-6 N m) is twice the hanging
# strand's w l2 R (4.8e-6 N m), which the heavy-rope oracle neglects; ten
# times longer it is 1/500 of it
NYLON_CAPSTAN_SCALE = 10.0


def nylon_capstan(rows):
    """The heavy-rope capstan (`O.capstan_scaled(NYLON_CAPSTAN_SCALE)`) as
    one yarn of the nylon monofilament in every tool, one bisection each
    (`capstan`). yarnsim on the yarn's vertices (`capstan-preset`);
    MuJoCo with the preset's mass and EI at 150 and 300 elements (50 put
    the 14 cm chords 2.5 mm inside the 1 m drum, more than the rope's 1 mm
    radius: it slid at 1.4 mu*); PyElastica at a 5 cm radius (the
    rotational mode of a thinner rope needs a smaller step: 2 cm ran at dt
    1e-5 but not at 4e-5; the bend matrix is EI whatever the radius)."""
    c = O.capstan_scaled(NYLON_CAPSTAN_SCALE)
    mat = O.preset_chain(NYLON)
    for integ, name in [("implicit-vertices", "vertices-implicit"),
                        ("midpoint-vertices", "vertices-midpoint")]:
        capstan("yarnsim", lambda mu, integ=integ: yarnsim_rope.capstan_preset_slides(
            NYLON, NYLON_CAPSTAN_SCALE, mu, integ, 1e-2), "184 vertices, no grid, dt 1e-2",
            name, rows, "capstan-nylon", c)
    for n in (150, 300):
        capstan("mujoco", lambda mu, n=n: mujoco_rope.capstan_slides(n, 1e-3, mu, c=c,
                                                                      material=mat),
                f"{n} elements, dt 1e-3, r 1 mm", "discrete", rows, "capstan-nylon", c)
    capstan("pyelastica", lambda mu: elastica_rope.capstan_slides(
        70, mu, dt=4e-5, radius=0.05, c=c, material=mat), "70 elements, dt 4e-5, r 5 cm",
        "position-verlet", rows, "capstan-nylon", c, rope_radius=0.05)


def bundle_preset(rows, duration, rounds, presets):
    """The reference bundle with one real yarn of each preset per yarn:
    yarnsim with the preset (`[time] axial = "implicit"`, APIC, dt auto)
    against MuJoCo's planar armature set-up with the preset's mass per
    rope (tex 1e-6 kg/m, see `oracles.preset_bundle`), its EI and yarn
    friction; the two alternate over `rounds` rounds (order swapped each
    round)."""
    for name in presets:
        mat = O.preset_bundle(name)
        runs = [
            ("yarnsim", "mpm-axial-implicit", f"{name}, 256^2, APIC, axial implicit, dt auto",
             lambda: yarnsim_rope.bundle(duration, "explicit", "auto", options=(
                 f"preset={name}", "apic", "axial-implicit"))),
            ("mujoco", "discrete", f"{name}, CG, dt 1e-3, r 1.9 mm, planar (y armature "
             f"{1e6 * mat['rho']:.3g})", lambda: mujoco_rope.bundle(duration, material=mat)),
        ]
        results = [[], []]
        for r in range(rounds):
            for i in ([0, 1] if r % 2 == 0 else [1, 0]):
                res = runs[i][3]()
                results[i].append(res)
                print(f"  round {r + 1} bundle-preset {runs[i][0]:10s} {name}: "
                      f"{res['wall_s']:.2f} s wall for {res['sim_s']:.3f} s; {_windows(res)}",
                      flush=True)
        ys, row_y = _bundle_row("bundle-preset", *runs[0][:3], results[0])
        mj, row_m = _bundle_row("bundle-preset", *runs[1][:3], results[1])
        ratio = row_m["wall_s_per_sim_s"] / row_y["wall_s_per_sim_s"]
        per_round = ", ".join(f"{m['wall_s'] / y['wall_s']:.3g}"
                              for y, m in zip(results[0], results[1]))
        d = _distances(ys, mj)
        row_m["note"] += (f"; against yarnsim: {d}; MuJoCo / yarnsim wall {ratio:.3g} (medians; "
                          f"per round {per_round})")
        print(f"  bundle-preset {name}: MuJoCo / yarnsim {ratio:.3g}; {d}", flush=True)
        rows += [row_y, row_m]


def bundle_converged(rows, duration):
    """MuJoCo's bundle (planar armature set-up) at dt 1e-3 and 5e-4 and
    yarnsim's converged setting (per-yarn FLIP at dt 5e-6: the step within
    1 cm of the shipped reference trajectory, its dt/2, in the centre of
    mass over the whole second, docs/performance/bundle-convergence.md),
    each run once
    (MuJoCo, yarnsim, MuJoCo): MuJoCo's own convergence (the two steps'
    frames apart) and the tools' centres of mass apart."""
    mj1 = mujoco_rope.bundle(duration, dt=1e-3)
    ys = yarnsim_rope.bundle(duration, "explicit", "5e-6", options=("per-yarn",))
    mj2 = mujoco_rope.bundle(duration, dt=5e-4)
    _, row_y = _bundle_row("bundle-converged", "yarnsim", "mpm-explicit",
                           "256^2, per-yarn FLIP, dt 5e-6", [ys])
    own = _distances(mj1, mj2)
    _, row_1 = _bundle_row("bundle-converged", "mujoco", "discrete",
                           "CG, dt 1e-3, r 1.9 mm, planar (y armature 1e6)", [mj1],
                           f"; against yarnsim: {_distances(ys, mj1)}")
    _, row_2 = _bundle_row("bundle-converged", "mujoco", "discrete",
                           "CG, dt 5e-4, r 1.9 mm, planar (y armature 1e6)", [mj2],
                           f"; against dt 1e-3: {own}; against yarnsim: {_distances(ys, mj2)}")
    print(f"  bundle-converged MuJoCo dt 1e-3 against 5e-4: {own}", flush=True)
    rows += [row_y, row_1, row_2]


# The ladders of `bundle-ladder`: yarnsim's converged setting of the stiff
# bundle (FLIP with `flip_time` 2 ms, the axial solve, `dt = "auto"`) at
# the default safety factor 0.8, then 0.6 (the stiff bundle's converged
# setting, docs/performance/cost.md) and its halvings (the mean step
# follows the factor); MuJoCo's planar armature set-up at dt 1e-3 and its
# halvings.
LADDER_YARNSIM = (0.8, 0.6, 0.3, 0.15)
LADDER_MUJOCO = (1e-3, 5e-4, 2.5e-4, 1.25e-4, 6.25e-5)
# a run is converged at T when its centre of mass stays within T (m) of
# every finer run of its ladder and of itself with gravity changed by
# PERTURB over the whole second (frames every 0.1 s)
LADDER_TOLS = (0.01, 0.02, 0.03, 0.05)
# the relative change of gravity of the perturbed runs: how far a 1e-9
# change moves the bundle (no step brings two runs closer than that)
PERTURB = 1e-9


def _com_apart(a, b):
    d = bundle_metrics.frame_distances(a["frames"], b["frames"])
    return d["com_max"] if d else float("nan")


def bundle_ladder(rows, duration, name, finest_mujoco=None):
    """The bundle with one real yarn of preset `name` per rope at a ladder
    of steps in each tool (`LADDER_YARNSIM`, `LADDER_MUJOCO`, and
    `finest_mujoco` (s) below them if given), one run each, the tools in
    turn, then every run but the finest with gravity changed by
    `PERTURB`. Each row's note gives how far its centre of mass lies from
    the finer runs of its ladder and from its perturbed twin (at most,
    over the second): its self-convergence and its sensitivity, the error
    estimate of a scene without an oracle.
    The tools are compared at each tolerance of `LADDER_TOLS` through
    their cheapest run converged at it; where a tool has none the
    comparison is a bound, against its finest run."""
    g = O.BUNDLE["g"]
    mat = O.preset_bundle(name)
    base = (f"preset={name}", "axial-implicit", "time.dt=auto", "transfer.flip_time=0.002")

    def ys(safety, extra=()):
        return yarnsim_rope.bundle(duration, "explicit", "auto",
                                   options=(*base, f"time.safety={safety}", *extra))

    def mj(dt, material=mat):
        return mujoco_rope.bundle(duration, dt=dt, material=material)

    ladders = {"yarnsim": list(LADDER_YARNSIM),
               "mujoco": list(LADDER_MUJOCO) + ([finest_mujoco] if finest_mujoco else [])}
    run = {"yarnsim": ys, "mujoco": mj}
    runs = {"yarnsim": [], "mujoco": []}
    for i in range(max(len(x) for x in ladders.values())):
        for tool in ("yarnsim", "mujoco"):
            if i < len(ladders[tool]):
                res = run[tool](ladders[tool][i])
                runs[tool].append(res)
                print(f"  bundle-ladder {tool:8s} {ladders[tool][i]:g}: {res['wall_s']:.2f} s "
                      f"wall for {res['sim_s']:.3f} s", flush=True)
    # every run but the finest again with gravity changed by PERTURB (not
    # timed): how far a change far below any step's error moves it
    perturbed = {
        "yarnsim": [ys(x, (f"gravity=[0.0, {-g * (1 + PERTURB)!r}]",))
                    for x in ladders["yarnsim"][:-1]],
        "mujoco": [mj(x, dict(mat, g=g * (1 + PERTURB))) for x in ladders["mujoco"][:-1]],
    }
    ladder_rows = {"yarnsim": [], "mujoco": []}
    for tool in ("yarnsim", "mujoco"):
        rs, ladder = runs[tool], ladders[tool]
        for i, res in enumerate(rs):
            apart = [_com_apart(res, finer) for finer in rs[i + 1:]]
            moved = _com_apart(res, perturbed[tool][i]) if apart else float("nan")
            # its accuracy: the farthest finer run, or the perturbed one
            err = max(apart + [moved]) if apart else float("nan")
            if tool == "yarnsim":
                integ = "mpm-axial-implicit"
                setting = (f"{name}, 256^2, FLIP flip_time 2 ms, axial implicit, dt auto, "
                           f"safety {ladder[i]:g}")
            else:
                integ = "discrete"
                setting = f"{name}, CG, dt {ladder[i]:g}, r 1.9 mm, planar (y armature)"
            extra = ("; centre of mass from the finer runs of the ladder at most "
                     + ", ".join(f"{100 * d:.2f}" for d in apart) + " cm; with gravity "
                     f"changed by {PERTURB:g} it moves {100 * moved:.2f} cm at most"
                     if apart else "; the finest run of the ladder")
            _, row = _bundle_row("bundle-ladder", tool, integ, setting, [res], extra)
            rows.append(row)
            ladder_rows[tool].append((row, err))
    for tol in LADDER_TOLS:
        best = {t: next(((r, e) for r, e in ladder_rows[t] if e <= tol), None)
                for t in ladder_rows}
        ours = best["yarnsim"]
        if ours is None:
            print(f"  bundle-ladder at {100 * tol:g} cm: no yarnsim run converged", flush=True)
            continue
        theirs, bound = best["mujoco"], ""
        if theirs is None:
            theirs, bound = ladder_rows["mujoco"][-1], " or more (MuJoCo: none converged; its finest)"
        print(f"  bundle-ladder at {100 * tol:g} cm: yarnsim {ours[0]['setting']} "
              f"{ours[0]['wall_s_per_sim_s']:.3g} s/s; MuJoCo {theirs[0]['setting']} "
              f"{theirs[0]['wall_s_per_sim_s']:.3g} s/s; MuJoCo / yarnsim "
              f"{theirs[0]['wall_s_per_sim_s'] / ours[0]['wall_s_per_sim_s']:.3g}{bound}",
              flush=True)
    print(f"  bundle-ladder: the two finest runs' centres of mass at most "
          f"{100 * _com_apart(runs['yarnsim'][-1], runs['mujoco'][-1]):.2f} cm apart", flush=True)


def merge_rows(path, rows):
    """The rows of `path` whose case is not among `rows`' cases, then
    `rows` (a partial run replaces its own cases only)."""
    cases = {r["case"] for r in rows}
    old = []
    if os.path.exists(path):
        with open(path) as f:
            for r in csv.DictReader(f):
                if r["case"] in cases:
                    continue
                for k in ("error", "wall_s_per_sim_s", "wall_vs_yarnsim", "wall_s", "sim_s"):
                    r[k] = float(r[k])
                r["ok"] = r["ok"] == "True"
                old.append(r)
    return old + rows


TITLE = "Rod peers against analytic oracles, one thread ({date})"


def replot(path):
    rows = []
    with open(path) as f:
        for r in csv.DictReader(f):
            for k in ("error", "wall_s_per_sim_s"):
                r[k] = float(r[k])
            r["ok"] = r["ok"] == "True"
            rows.append(r)
    date = time.strftime("%Y-%m-%d", time.localtime(os.path.getmtime(path)))
    plot.work_precision(rows, os.path.splitext(path)[0] + ".svg", title=TITLE.format(date=date))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--rounds", type=int, default=3, choices=range(1, 100), metavar="N")
    ap.add_argument("--out", default=None)
    ap.add_argument("--skip-bundle", action="store_true")
    ap.add_argument("--bundle-duration", type=float, default=1.0,
                    help="simulated seconds of the bundle runs (the scene's whole second)")
    ap.add_argument("--bundle-implicit-duration", type=float, default=0.2,
                    help="simulated seconds of the grid implicit bundle run (~500 s/s)")
    ap.add_argument("--replot", metavar="CSV", help="only redraw the SVG next to CSV")
    ap.add_argument("--only", metavar="GROUPS",
                    help="comma-separated: bundle-preset, bundle-converged, bundle-ladder, nylon; "
                         "runs only "
                         "those and replaces their cases' rows in the existing CSV")
    ap.add_argument("--finest-mujoco", type=float, default=None, metavar="DT",
                    help="bundle-ladder: one more MuJoCo step below the ladder's (s)")
    ap.add_argument("--presets", default="polyester-167dtex,nylon66-mono-0.30mm",
                    help="the presets of bundle-preset (comma-separated)")
    a = ap.parse_args()
    if a.replot:
        replot(a.replot)
        return
    out = a.out or (tempfile.gettempdir() if a.quick else os.path.join(ROOT, "docs",
                                                                        "performance"))
    stem = "peers_quick" if a.quick else "peers"
    rounds = 1 if a.quick else a.rounds
    if not all(os.path.exists(b) for b in (yarnsim_rope.BIN, yarnsim_rope.CLI)):
        yarnsim_rope.build()
    # warm-up: Numba compiles PyElastica's kernels on the first run (cached)
    elastica_rope.chain(4, dt=1e-4, duration=0.01)
    if not a.quick:
        elastica_rope.capstan_slides(8, 0.3, load=1e-3, hold=1e-3)
    t_start = time.time()
    if a.only:
        groups = a.only.split(",")
        unknown = set(groups) - {"bundle-preset", "bundle-converged", "bundle-ladder", "nylon"}
        if unknown:
            ap.error(f"--only: unknown group(s) {', '.join(sorted(unknown))}")
        rows = []
        try:
            if "nylon" in groups:
                nylon(rows, rounds)
                nylon_capstan(rows)
            if "bundle-preset" in groups:
                bundle_preset(rows, a.bundle_duration, rounds, a.presets.split(","))
            if "bundle-converged" in groups:
                bundle_converged(rows, a.bundle_duration)
            if "bundle-ladder" in groups:
                for name in a.presets.split(","):
                    bundle_ladder(rows, a.bundle_duration, name, a.finest_mujoco)
        finally:
            # the rows of the groups that ran, also when a later one fails
            write(out, stem, merge_rows(os.path.join(out, stem + ".csv"), rows), t_start)
        return
    cs = cases(a.quick)
    res = interleave(cs, rounds)
    rows = []
    for i, (tool, integ, case, setting, _) in enumerate(cs):
        rs = res[i]
        wall = statistics.median(r["wall_s"] for r in rs)
        sim = rs[0]["sim_s"]
        rows.append(dict(tool=tool, integrator=integ, case=case, setting=setting,
                         error=rs[0]["error"], wall_s_per_sim_s=wall / sim, wall_s=wall,
                         sim_s=sim, rounds=len(rs), ok=all(r["ok"] for r in rs),
                         note=rs[0].get("note", "")))
    if not a.quick:
        capstan("yarnsim", lambda mu: yarnsim_rope.capstan_slides(
            O.CAPSTAN["radius"], O.CAPSTAN["l1"], O.CAPSTAN["l2"], mu),
            "184 vertices, 128^2, dt 1e-4", "mpm-explicit", rows)
        capstan("yarnsim", lambda mu: yarnsim_rope.capstan_slides(
            O.CAPSTAN["radius"], O.CAPSTAN["l1"], O.CAPSTAN["l2"], mu, "implicit", 1e-3),
            "184 vertices, 128^2, dt 1e-3", "mpm-implicit", rows)
        for integ, name in [("implicit-vertices", "vertices-implicit"),
                            ("midpoint-vertices", "vertices-midpoint")]:
            capstan("yarnsim", lambda mu, integ=integ: yarnsim_rope.capstan_slides(
                O.CAPSTAN["radius"], O.CAPSTAN["l1"], O.CAPSTAN["l2"], mu, integ, 1e-2),
                "184 vertices, no grid, dt 1e-2", name, rows)
        capstan("pyelastica", lambda mu: elastica_rope.capstan_slides(70, mu),
                "70 elements, dt 5e-5, c_v 50", "position-verlet", rows)
        for n in (50, 100):
            capstan("mujoco", lambda mu, n=n: mujoco_rope.capstan_slides(n, 1e-3, mu),
                    f"{n} elements, dt 1e-3", "discrete", rows)
        if not a.skip_bundle:
            bundle(rows, a.bundle_duration, a.bundle_implicit_duration, rounds)
    write(out, stem, rows, t_start)


def write(out, stem, rows, t_start):
    """The CSV and the SVG of `rows`, with `wall_vs_yarnsim`."""
    # ratios against yarnsim's first explicit setting of the same case (same
    # run), or its first row of the case where it has no explicit one; the
    # rows kept from an earlier run (`merge_rows`) keep theirs
    for r in (r for r in rows if "wall_vs_yarnsim" not in r):
        ours = [x for x in rows if x["tool"] == "yarnsim" and x["case"] == r["case"]]
        ref = next((x for x in ours if x["integrator"] == "mpm-explicit"),
                   ours[0] if ours else None)
        r["wall_vs_yarnsim"] = (r["wall_s_per_sim_s"] / ref["wall_s_per_sim_s"]
                                if ref and ref["wall_s_per_sim_s"] > 0 else float("nan"))
    os.makedirs(out, exist_ok=True)
    fields = ["tool", "integrator", "case", "setting", "error", "wall_s_per_sim_s",
              "wall_vs_yarnsim", "wall_s", "sim_s", "rounds", "ok", "note"]
    path = os.path.join(out, stem + ".csv")
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields)
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{r[k]:.6g}" if isinstance(r[k], float) else r[k]) for k in fields})
    svg = os.path.join(out, stem + ".svg")
    plot.work_precision(rows, svg, title=TITLE.format(date=time.strftime("%Y-%m-%d")))
    print(f"wrote {path} and {svg} ({time.time() - t_start:.1f} s)")


if __name__ == "__main__":
    main()
