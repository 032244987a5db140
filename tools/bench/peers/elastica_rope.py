"""PyElastica 1.0.0 entry: a Cosserat rod (explicit position Verlet),
set up as in the checked notes: radius r with E from the axial stiffness
(EA = E pi r^2) and the density from the line density (rho pi r^2), the
bend matrix overwritten (B = 1e-6 for the chain), a prestretched start for
the chain (rest lengths shortened to the hanging equilibrium, so the
stretched rope has the oracle's length and starts at rest without the
axial release transient), the step at about 0.7 l / c. The motion is in
the x-z plane (z up)."""

import math
import time

import numpy as np
from elastica import (
    BaseSystemCollection, Constraints, CosseratRod, Forcing, GravityForces,
    OneEndFixedBC, PositionVerlet,
)
from elastica.boundary_conditions import GeneralConstraint

import oracles as O


class _Sim(BaseSystemCollection, Constraints, Forcing):
    pass


def _directors(pos):
    """Directors (d1 = y, d3 = tangent) of every element of a rope in the
    x-z plane; shape (3, 3, n)."""
    t = np.diff(pos, axis=1)
    t /= np.linalg.norm(t, axis=0)
    n = t.shape[1]
    d = np.zeros((3, 3, n))
    d1 = np.array([0.0, 1.0, 0.0])
    for j in range(n):
        d3 = t[:, j]
        d[0, :, j] = d1
        d[1, :, j] = np.cross(d3, d1)
        d[2, :, j] = d3
    return d


def _run(sim, rod, dt, steps, probe):
    sim.finalize()
    stepper = PositionVerlet()
    out = np.empty(steps + 1)
    ts = np.arange(steps + 1) * dt
    out[0] = probe(rod)
    t = np.float64(0.0)
    t0 = time.perf_counter()
    for k in range(steps):
        t = stepper.step(sim, t, dt)
        out[k + 1] = probe(rod)
    return ts, out, time.perf_counter() - t0


def chain(elements, dt=None, radius=5e-3, duration=None, material=None):
    """The hanging chain; `material` (`k` EA in N, `rho` in kg/m,
    `bending` EI in N m^2, `radius` in m, `oracle` the period in s) makes
    it one real yarn, at the step 0.7 l / c with c = sqrt(EA / rho)
    unless `dt` is given."""
    p = dict(O.CHAIN, **(material or {}))
    L, g, k, rho = p["length"], p["g"], p["k"], p["rho"]
    radius = p.get("radius", radius)
    if dt is None:
        dt = (0.7 * (L / elements) / math.sqrt(k / rho) if material
              else 1.4e-4 * 25 / elements)
    area = math.pi * radius ** 2
    shape = O.chain_shape(elements)
    pos = np.array([[u for u, _ in shape], [0.0] * (elements + 1), [z - L for _, z in shape]])
    sim = _Sim()
    rod = CosseratRod.straight_rod(
        elements, np.zeros(3), np.array([0.0, 0.0, -1.0]), np.array([0.0, 1.0, 0.0]), L,
        radius, rho / area, youngs_modulus=k / area, position=pos, directors=_directors(pos))
    rod.bend_matrix[0, 0, :] = p.get("bending", 1e-6)
    rod.bend_matrix[1, 1, :] = p.get("bending", 1e-6)
    seg = np.linalg.norm(np.diff(pos, axis=1), axis=0)
    s_mid = np.cumsum(seg) - 0.5 * seg
    tension = rho * g * (L - s_mid)
    rod.rest_lengths[:] = seg / (1.0 + tension / k)
    sim.append(rod)
    # position only: fixing the first director as well would clamp the top
    # element's direction through the shear stiffness
    sim.constrain(rod).using(GeneralConstraint, constrained_position_idx=(0,),
                             constrained_director_idx=(0,),
                             translational_constraint_selector=np.array([True, True, True]),
                             rotational_constraint_selector=np.array([False, False, False]))
    sim.add_forcing_to(rod).using(GravityForces, acc_gravity=np.array([0.0, 0.0, -g]))
    steps = int(round((duration or p["duration"]) / dt))
    ts, us, wall = _run(sim, rod, dt, steps, lambda r: r.position_collection[0, -1])
    period, nc = O.zero_crossing_period(ts, us)
    oracle = p.get("oracle") or O.chain_period()
    return dict(ok=bool(np.all(np.isfinite(us))), error=(period - oracle) / oracle, wall_s=wall,
                sim_s=steps * dt, crossings=nc, dt=dt)


def cantilever(elements):
    """Clamped at node 0 (position and the first element's director), B = 1,
    EA = 1e4 (r = 0.02), G = E / 3 (the default: shear adds about +0.5 %);
    undamped (position Verlet does not dissipate), the tip deflection
    averaged over two measured periods of the first mode, as yarnsim's test,
    against q L_f^4 / (8 B) with L_f = L - l / 2 as for the other tools (the
    first bending couple sits at node 1, a Voronoi length from the clamp:
    against the full L it is -7.4 % at 25 elements)."""
    p = O.CANTILEVER
    L, B, rho = p["length"], p["bending"], p["rho"]
    g = O.cantilever_gravity(p)
    radius = 0.02
    area = math.pi * radius ** 2
    young = 4.0 * B / (math.pi * radius ** 4)
    c = math.sqrt(young * area / rho)
    dt = 0.5 * (L / elements) / c
    sim = _Sim()
    rod = CosseratRod.straight_rod(
        elements, np.zeros(3), np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]), L,
        radius, rho / area, youngs_modulus=young, shear_modulus=young / 3.0)
    sim.append(rod)
    sim.constrain(rod).using(OneEndFixedBC, constrained_position_idx=(0,),
                             constrained_director_idx=(0,))
    sim.add_forcing_to(rod).using(GravityForces, acc_gravity=np.array([0.0, 0.0, -g]))
    free = L - 0.5 * L / elements
    steps = int(round(2.5 * 2 * math.pi / O.cantilever_omega1(free, p) / dt))
    _, d, wall = _run(sim, rod, dt, steps, lambda r: -r.position_collection[2, -1])
    tip = O.mean_over_two_periods(list(d[1:]))
    oracle = O.cantilever_tip(free, p)
    return dict(ok=bool(np.all(np.isfinite(d))), error=(tip - oracle) / oracle, wall_s=wall,
                sim_s=steps * dt, dt=dt)


def capstan_slides(elements, mu, dt=5e-5, radius=2e-3, k_contact=1e4, nu=10.0, c_v=50.0,
                   load_damping=20.0, load=None, hold=None, c=None, material=None):
    """The heavy rope over a fixed rigid cylinder (axis y) with
    `RodCylinderContact` (spring k, dashpot nu, Coulomb friction mu
    regularised by the slip-velocity coefficient c_v), EA = 1000 as yarnsim's
    capstan, B = 1e-6, g = 2. The rope starts on the surface (centreline at
    R + r); its velocity is damped (rate `load_damping` 1/s) during the
    0.2 s load, then it holds 1 s undamped: slid if a free end moved
    vertically by more than 0.5 % of its hanging length. Returns (slid,
    wall seconds, simulated seconds). `c` replaces `O.CAPSTAN`
    (`O.capstan_scaled`); `material` (`k` EA in N, `rho` kg/m, `bending`
    EI in N m^2: `O.preset_chain`) the rope (the contact's spring and
    dashpot then scale with its line density, so that the contact's
    frequency and damping ratio stay those of the 1 kg/m rope)."""
    from elastica import Contact, Cylinder, RodCylinderContact

    class Sim(BaseSystemCollection, Constraints, Forcing, Contact):
        pass

    c = c or O.CAPSTAN
    rho, ea, bend = ((material["rho"], material["k"], material["bending"]) if material
                     else (1.0, 1000.0, 1e-6))
    k_contact, nu = k_contact * rho, nu * rho
    R, l1, l2, g = c["radius"], c["l1"], c["l2"], c["g"]
    Rc = R + radius
    pts, total = O.capstan_centreline(elements, Rc, c)
    pos = np.array([[x for x, _ in pts], [0.0] * (elements + 1), [z for _, z in pts]])
    area = math.pi * radius ** 2
    sim = Sim()
    rod = CosseratRod.straight_rod(
        elements, pos[:, 0], np.array([0.0, 0.0, 1.0]), np.array([0.0, 1.0, 0.0]), total,
        radius, rho / area, youngs_modulus=ea / area, position=pos,
        directors=_directors(pos))
    rod.bend_matrix[0, 0, :] = bend
    rod.bend_matrix[1, 1, :] = bend
    rod.rest_lengths[:] = np.linalg.norm(np.diff(pos, axis=1), axis=0)
    cyl = Cylinder(np.array([0.0, -0.05, 0.0]), np.array([0.0, 1.0, 0.0]),
                   np.array([1.0, 0.0, 0.0]), 0.1, R, 1e3)
    sim.append(rod)
    sim.append(cyl)
    sim.add_forcing_to(rod).using(GravityForces, acc_gravity=np.array([0.0, 0.0, -g]))
    sim.detect_contact_between(rod, cyl).using(
        RodCylinderContact, k=k_contact, nu=nu, velocity_damping_coefficient=c_v,
        friction_coefficient=mu)
    sim.finalize()
    stepper = PositionVerlet()
    t = np.float64(0.0)
    n_load = int(round((c["load"] if load is None else load) / dt))
    n_hold = int(round((c["hold"] if hold is None else hold) / dt))
    decay = math.exp(-load_damping * dt)
    t0 = time.perf_counter()
    for _ in range(n_load):
        t = stepper.step(sim, t, dt)
        rod.velocity_collection *= decay
        cyl.velocity_collection[:] = 0.0
        cyl.omega_collection[:] = 0.0
    a0, b0 = rod.position_collection[2, 0], rod.position_collection[2, -1]
    slid = False
    for k in range(n_hold):
        t = stepper.step(sim, t, dt)
        cyl.velocity_collection[:] = 0.0
        cyl.omega_collection[:] = 0.0
        if k % 50 == 49:
            rel = max(abs(rod.position_collection[2, 0] - a0) / l1,
                      abs(rod.position_collection[2, -1] - b0) / l2)
            if not np.isfinite(rel) or rel > c["slip"]:
                slid = True
                break
    return slid, time.perf_counter() - t0, float(t)
