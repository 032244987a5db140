"""MuJoCo 4.0.0 entry: a 1D `flexcomp` (discrete elastic rod) with the
`discrete` (implicit) integrator, set up as in the checked notes:
E = 4 B / (pi r^4), point masses rho l (free ends rho l / 2) through
`model.body_mass`, edges as equality constraints (solref tau 1e-4 for the
chain, 1e-3 otherwise), elliptic friction cone with impratio 100 and contact
solref 2e-3 for the capstan. MuJoCo's z axis is yarnsim's y (the rope
moves in the x-z plane)."""

import math
import time

import mujoco
import numpy as np

import oracles as O


def _rope_xml(name, pts, radius, mass, young, tau, pin, extra="", contact=""):
    point = " ".join(f"{x:.9f} 0 {z:.9f}" for x, z in pts)
    element = " ".join(f"{i} {i + 1}" for i in range(len(pts) - 1))
    pin_xml = f'<pin id="{" ".join(str(i) for i in pin)}"/>' if pin else ""
    return (
        f'<flexcomp name="{name}" type="direct" dim="1" radius="{radius}" mass="{mass}" '
        f'point="{point}" element="{element}" {extra}>'
        f'<edge equality="true" solref="{tau} 1"/>'
        f'<elasticity young="{young}"/>{contact}{pin_xml}</flexcomp>'
    )


def _set_masses(m, name, seglen, rho):
    """Masses rho l per interior point and rho l / 2 at the ends."""
    f = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_FLEX, name)
    adr, num = m.flex_vertadr[f], m.flex_vertnum[f]
    bodies = m.flex_vertbodyid[adr:adr + num]
    for k, b in enumerate(bodies):
        if b > 0:
            m.body_mass[b] = rho * seglen * (0.5 if k in (0, num - 1) else 1.0)
    return adr, num


def _refresh(m):
    """Recompute the derived constants after the mass edit (without this
    the chain's period is +1.7 % instead of +0.05 % at 25 elements)."""
    mujoco.mj_setConst(m, mujoco.MjData(m))


def chain(elements, dt, tau=1e-4, material=None):
    """The hanging chain; `material` (`rho` in kg/m, `bending` EI in
    N m^2, `oracle` the period in s) makes it one real yarn: E = 4 EI /
    (pi r^4) at r = 1 mm, the top point pinned (no moment there)."""
    p = dict(O.CHAIN, **(material or {}))
    L = p["length"]
    young = 4.0 * p.get("bending", 0.0) / (math.pi * 1e-3 ** 4)
    shape = O.chain_shape(elements)
    pts = [(u, z - L) for u, z in shape]  # pin at the origin
    xml = (
        f'<mujoco><option gravity="0 0 {-p["g"]}" integrator="discrete" timestep="{dt}"><flag refsafe="disable"/></option>'
        f"<worldbody>{_rope_xml('rope', pts, 1e-3, p['rho'] * L, young, tau, [0])}</worldbody>"
        "</mujoco>"
    )
    m = mujoco.MjModel.from_xml_string(xml)
    adr, num = _set_masses(m, "rope", L / elements, p["rho"])
    _refresh(m)
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    steps = int(round(p["duration"] / dt))
    ts = np.empty(steps + 1)
    us = np.empty(steps + 1)
    ts[0], us[0] = 0.0, d.flexvert_xpos[adr + num - 1, 0]
    t0 = time.perf_counter()
    for k in range(steps):
        mujoco.mj_step(m, d)
        ts[k + 1] = d.time
        us[k + 1] = d.flexvert_xpos[adr + num - 1, 0]
    wall = time.perf_counter() - t0
    period, nc = O.zero_crossing_period(ts, us)
    oracle = p.get("oracle") or O.chain_period()
    ok = bool(np.all(np.isfinite(us))) and d.time > 0.99 * p["duration"]
    return dict(ok=ok, error=(period - oracle) / oracle, wall_s=wall, sim_s=steps * dt,
                crossings=nc)


def cantilever(elements, dt, duration=3.0, rate=20.0):
    """Clamped (points 0 and 1 pinned) beam of length L along +x under its
    weight, damped to rest (joint damping rho l `rate` per point, a damping
    rate of 20 1/s independent of the resolution: the first mode,
    omega_1 = 14 1/s, decays as exp(-10 t), to 1e-13 in the 3 s); the tip
    deflection at the end against q L_f^4 / (8 B),
    L_f = L - l / 2. (The undamped two-period mean that the explicit tools
    use is biased here: the implicit `discrete` step dissipates, +0.6 % at
    25 elements.)"""
    p = O.CANTILEVER
    L, B, rho = p["length"], p["bending"], p["rho"]
    g = O.cantilever_gravity(p)
    r = 1e-3
    young = 4.0 * B / (math.pi * r ** 4)
    pts = [(L * i / elements, 0.0) for i in range(elements + 1)]
    xml = (
        f'<mujoco><option gravity="0 0 {-g}" integrator="discrete" timestep="{dt}"/>'
        f"<worldbody>{_rope_xml('beam', pts, r, rho * L, young, 1e-3, [0, 1])}</worldbody></mujoco>"
    )
    m = mujoco.MjModel.from_xml_string(xml)
    adr, num = _set_masses(m, "beam", L / elements, rho)
    _refresh(m)
    m.dof_damping[:] = rate * rho * L / elements
    d = mujoco.MjData(m)
    free = L - 0.5 * L / elements
    steps = int(round(duration / dt))
    defl = np.empty(steps)
    t0 = time.perf_counter()
    for k in range(steps):
        mujoco.mj_step(m, d)
        defl[k] = -d.flexvert_xpos[adr + num - 1, 2]
    wall = time.perf_counter() - t0
    tip = defl[-1]
    oracle = O.cantilever_tip(free, p)
    return dict(ok=bool(np.all(np.isfinite(defl))), error=(tip - oracle) / oracle, wall_s=wall,
                sim_s=steps * dt)


def capstan_slides(elements, dt, mu, radius=1e-3, c=None, material=None):
    """Heavy rope over a half cylinder (axis y) with friction mu on both the
    rope and the cylinder (MuJoCo takes the larger). Loads for 0.2 s, then
    holds 1 s: slid if a free end moved vertically by more than 0.5 % of its
    hanging length. Returns (slid, wall seconds, simulated seconds). `c`
    replaces `O.CAPSTAN` (`O.capstan_scaled`); `material` (`rho` in kg/m,
    `bending` EI in N m^2: `O.preset_chain`) the bending-free rope of 1
    kg/m."""
    c = c or O.CAPSTAN
    rho = material["rho"] if material else 1.0
    young = 4.0 * material["bending"] / (math.pi * radius ** 4) if material else 0
    R, l1, l2 = c["radius"], c["l1"], c["l2"]
    Rc = R + radius  # the centreline lies on the cylinder surface
    pts, total = O.capstan_centreline(elements, Rc, c)
    fr = f"{mu} 0.005 0.0001"
    contact = f'<contact condim="3" friction="{fr}" solref="2e-3 1" selfcollide="none"/>'
    xml = (
        f'<mujoco><option gravity="0 0 {-c["g"]}" integrator="discrete" timestep="{dt}" '
        f'cone="elliptic" impratio="100"/><worldbody>'
        f'<geom type="cylinder" size="{R} 0.05" euler="90 0 0" friction="{fr}" solref="2e-3 1"/>'
        f"{_rope_xml('rope', pts, radius, rho * total, young, 1e-3, [], contact=contact)}"
        f"</worldbody></mujoco>"
    )
    m = mujoco.MjModel.from_xml_string(xml)
    adr, num = _set_masses(m, "rope", total / elements, rho)
    _refresh(m)
    d = mujoco.MjData(m)
    t0 = time.perf_counter()
    for _ in range(int(round(c["load"] / dt))):
        mujoco.mj_step(m, d)
    a0, b0 = d.flexvert_xpos[adr, 2], d.flexvert_xpos[adr + num - 1, 2]
    slid = False
    for k in range(int(round(c["hold"] / dt))):
        mujoco.mj_step(m, d)
        if k % 10 == 9:
            rel = max(abs(d.flexvert_xpos[adr, 2] - a0) / l1,
                      abs(d.flexvert_xpos[adr + num - 1, 2] - b0) / l2)
            if not np.isfinite(rel) or rel > c["slip"]:
                slid = True
                break
    return slid, time.perf_counter() - t0, d.time


def bundle(duration, dt=1e-3, radius=0.0019, planar="armature", tolerance=1e-8, material=None,
           frame=0.1):
    """The reference bundle: 12 ropes x 200 points falling onto three
    cylinders, rope-rope and rope-cylinder friction, floor and side walls,
    CG solver. Two ways to keep it in the x-z plane (free 3D drifts out):
    `planar="armature"` gives every out-of-plane (y) slide joint an
    armature of 1e6 kg (the driver reports the remaining drift);
    `planar="delete"` deletes those 2,400 joints in the spec, a truly 2D
    model (the compile takes about a minute, not timed). Returns the wall
    time, per window the mean CG iterations per step (of the island that
    took the most), the share of steps at the iteration cap and the mean
    contacts per step, the wall time per window (`windows`: [start, end,
    wall] for the fall and landing up to `BUNDLE["landed"]` s, then the
    rest), every rope's points in yarnsim's plane at the end and every
    `frame` s (`frames`: [time, ropes], not timed). `material` overrides
    `rho` (kg/m per rope), `bending` (N m^2) and `yarn_friction` of
    `BUNDLE` (a preset's yarn: `oracles.preset_bundle`); the armature of
    the planar set-up scales with `rho` (1e6 kg at 1 kg/m), so the model is
    the reference one with its masses scaled, as far as the masses enter."""
    b = dict(O.BUNDLE, **(material or {}))
    n = b["vertices"] - 1
    seg = b["length"] / n
    young = 4.0 * b["bending"] / (math.pi * radius ** 4)
    fr = f'{b["yarn_friction"]} 0.005 0.0001'
    contact = f'<contact condim="3" friction="{fr}" solref="2e-3 1" selfcollide="none"/>'
    ropes = []
    for j in range(b["yarns"]):
        y0 = b["start"][1] + j * b["spacing"]
        pts = [(b["start"][0] + seg * i, y0) for i in range(n + 1)]
        ropes.append(_rope_xml(f"r{j}", pts, radius, b["rho"] * b["length"], young, 1e-3, [],
                               contact=contact))
    cf = f'{b["cyl_friction"]} 0.005 0.0001'
    cyls = "".join(
        f'<geom type="cylinder" size="{b["cyl_radius"]} 0.1" pos="{x} 0 {z}" euler="90 0 0" '
        f'friction="{cf}"/>' for x, z in b["cylinders"])
    wall = 3.0 / 256.0
    planes = (f'<geom type="plane" size="1 1 0.01" pos="0.5 0 {wall}"/>'
              f'<geom type="plane" size="1 1 0.01" pos="{wall} 0 0.5" zaxis="1 0 0"/>'
              f'<geom type="plane" size="1 1 0.01" pos="{1 - wall} 0 0.5" zaxis="-1 0 0"/>')
    xml = (
        f'<mujoco><option gravity="0 0 {-b["g"]}" integrator="discrete" timestep="{dt}" '
        f'solver="CG" tolerance="{tolerance}" cone="elliptic" impratio="10"/><worldbody>{planes}{cyls}'
        f'{"".join(ropes)}</worldbody></mujoco>'
    )
    if planar == "delete":
        spec = mujoco.MjSpec.from_string(xml)
        spec.compile()  # the flexcomp's bodies and joints exist after a compile
        for j in [j for j in spec.joints if abs(j.axis[1]) > 0.5]:
            spec.delete(j)
        m = spec.compile()
    elif planar == "armature":
        m = mujoco.MjModel.from_xml_string(xml)
    else:
        raise ValueError(f"planar must be armature or delete, got {planar!r}")
    spans = [_set_masses(m, f"r{j}", seg, b["rho"]) for j in range(b["yarns"])]
    if planar == "armature":
        for j in range(m.njnt):
            if abs(m.jnt_axis[j][1]) > 0.5:
                m.dof_armature[m.jnt_dofadr[j]] = 1e6 * b["rho"]
    _refresh(m)
    d = mujoco.MjData(m)
    windows = []
    # CG iterations per step (the most of any constraint island: each rope
    # is an island of its own until they touch) and contacts per step,
    # summed per window
    iters, contacts, steps, capped = [], [], [], []
    mujoco.mj_forward(m, d)  # the positions of the first frame

    def ropes():
        x = d.flexvert_xpos
        return [np.column_stack([x[a:a + k, 0], x[a:a + k, 2]]) for a, k in spans]

    frames = [[0.0, ropes()]]
    every = max(1, int(round(frame / dt)))
    untimed = 0.0
    t0 = time.perf_counter()
    start = 0.0
    cap = int(m.opt.iterations)
    for end in sorted({min(b["landed"], duration), duration}):
        w0 = time.perf_counter()
        it = con = nsteps = at_cap = 0
        w_untimed = 0.0
        for _ in range(int(round((end - start) / dt))):
            mujoco.mj_step(m, d)
            k = int(d.solver_niter[:max(1, min(d.nisland, len(d.solver_niter)))].max())
            it += k
            at_cap += k >= cap
            con += d.ncon
            nsteps += 1
            if int(round(d.time / dt)) % every == 0:
                f0 = time.perf_counter()
                frames.append([d.time, ropes()])
                w_untimed += time.perf_counter() - f0
        windows.append([start, d.time, time.perf_counter() - w0 - w_untimed])
        untimed += w_untimed
        iters.append(it)
        contacts.append(con)
        steps.append(nsteps)
        capped.append(at_cap)
        start = end
    wall_s = time.perf_counter() - t0 - untimed
    x = d.flexvert_xpos
    yarns = ropes()
    drift = float(np.max(np.abs(x[:, 1])))
    return dict(ok=bool(np.all(np.isfinite(x))) and d.time > 0.99 * duration, wall_s=wall_s,
                sim_s=d.time, yarns=yarns, out_of_plane=drift, windows=windows, frames=frames,
                solver_iterations=[i / max(n, 1) for i, n in zip(iters, steps)],
                contacts=[c / max(n, 1) for c, n in zip(contacts, steps)],
                at_cap=[c / max(n, 1) for c, n in zip(capped, steps)], iteration_cap=cap)
