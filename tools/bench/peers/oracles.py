"""Analytic oracles of the benchmark, the same as yarnsim's oracle tests
(`tests/yarn_oracles.rs`): the hanging chain's first mode, the
Euler-Bernoulli cantilever and the heavy-rope capstan threshold."""

import math

J01 = 2.404825557695773  # first zero of J0

# Shared parameters (tests/yarn_oracles.rs)
CHAIN = dict(length=0.8, g=9.8, amplitude=0.02, duration=3.4, k=2000.0, rho=1.0)
CANTILEVER = dict(length=0.5, bending=1.0, rho=1.0)  # g = 0.08 B / (rho L^3)
CAPSTAN = dict(radius=0.1, l1=0.1, l2=0.3, g=2.0, load=0.2, hold=1.0, slip=0.005)
BUNDLE = dict(
    yarns=12, vertices=200, length=0.8, start=(0.1, 0.75), spacing=0.01, rho=1.0,
    k=1000.0, bending=1e-3, yarn_friction=0.05, g=9.8,
    cylinders=[(0.25, 0.6), (0.5, 0.3), (0.75, 0.5)], cyl_radius=0.08, cyl_friction=0.3,
    box=(0.0, 1.0),
    # end of the first timed window (s): the fall and the landing on the top
    # circle (about 0.1 s); `BUNDLE_LANDED` in evidence/examples/peers_chain.rs
    landed=0.2,
)


def bessel_j0(x):
    """J0 by its power series (enough terms for x < 3)."""
    s, term, k = 0.0, 1.0, 0
    while abs(term) > 1e-17 or k < 3:
        s += term
        k += 1
        term *= -(x * x / 4.0) / (k * k)
    return s


def chain_period(length=CHAIN["length"], g=CHAIN["g"]):
    """Period of the first mode of the uniform inextensible hanging chain,
    omega_1 = (j01 / 2) sqrt(g / L)."""
    return 2.0 * math.pi / (0.5 * J01 * math.sqrt(g / length))


def chain_shape(n, length=CHAIN["length"], amp=CHAIN["amplitude"]):
    """Points (horizontal offset, height above the free end) from the pin
    down: the first mode u(z) = A J0(j01 sqrt(z / L)), z up from the free end."""
    out = []
    for i in range(n + 1):
        z = length * (n - i) / n
        out.append((amp * bessel_j0(J01 * math.sqrt(z / length)), z))
    return out


def zero_crossing_period(ts, us):
    """Twice the mean spacing of the zero crossings of u(t) (linear
    interpolation within a step); NaN with fewer than two crossings."""
    cr = []
    for k in range(1, len(us)):
        a, b = us[k - 1], us[k]
        if a * b < 0.0:
            cr.append(ts[k] - (ts[k] - ts[k - 1]) * b / (b - a))
    if len(cr) < 2:
        return float("nan"), len(cr)
    return 2.0 * (cr[-1] - cr[0]) / (len(cr) - 1), len(cr)


def cantilever_gravity(p=CANTILEVER):
    return 0.08 * p["bending"] / (p["rho"] * p["length"] ** 3)


def cantilever_tip(free_length, p=CANTILEVER):
    """Euler-Bernoulli tip deflection q L_f^4 / (8 B)."""
    q = p["rho"] * cantilever_gravity(p)
    return q * free_length ** 4 / (8.0 * p["bending"])


def cantilever_omega1(free_length, p=CANTILEVER):
    return 1.8751 ** 2 * math.sqrt(p["bending"] / (p["rho"] * free_length ** 4))


def mean_over_two_periods(d):
    """Mean of a deflection history over two measured periods of its
    oscillation about its mean (first to third upward crossing), as the
    yarnsim test measures; the mean of the last half if it does not swing."""
    m0 = sum(d) / len(d)
    up = [k for k in range(1, len(d)) if d[k - 1] < m0 <= d[k]]
    if len(up) >= 3:
        seg = d[up[0]:up[2]]
    else:
        seg = d[len(d) // 2:]
    return sum(seg) / len(seg)


def capstan_centreline(elements, rc, c=CAPSTAN):
    """The capstan rope's centreline at `elements + 1` evenly spaced points
    (x, z): up from `l1` below the centre on the left, over the half circle
    of radius `rc` (the cylinder's radius plus the rope's), down to `l2` on
    the right. Returns (points, total length)."""
    l1, l2 = c["l1"], c["l2"]
    total = l1 + l2 + math.pi * rc
    pts = []
    for i in range(elements + 1):
        s = total * i / elements
        if s <= l1:
            pts.append((-rc, -l1 + s))
        elif s <= l1 + math.pi * rc:
            psi = math.pi - (s - l1) / rc
            pts.append((rc * math.cos(psi), rc * math.sin(psi)))
        else:
            pts.append((rc, -(s - l1 - math.pi * rc)))
    return pts, total


def capstan_tension(mu, r, w, l1, n=2000):
    """Tension at the heavy end of the wrapped half circle: dT/ds = mu T / R
    + w (mu sin psi - cos psi), psi = pi - s / R, T(0) = w l1 (RK4)."""
    def f(s, t):
        psi = math.pi - s / r
        return mu * t / r + w * (mu * math.sin(psi) - math.cos(psi))
    h = math.pi * r / n
    t = w * l1
    for i in range(n):
        s = i * h
        k1 = f(s, t)
        k2 = f(s + h / 2, t + h / 2 * k1)
        k3 = f(s + h / 2, t + h / 2 * k2)
        k4 = f(s + h, t + h * k3)
        t += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return t


def capstan_scaled(scale):
    """`CAPSTAN` with its lengths times `scale` and its load and hold times
    `sqrt(scale)`: the same motion in units of the hanging lengths (Froude
    scaling), the same mu* (`capstan_threshold` depends on the ratios of
    the lengths only), while a yarn's bending moment EI / R against the
    hanging tension's moment shrinks as 1 / scale^3."""
    c = dict(CAPSTAN)
    for k in ("radius", "l1", "l2"):
        c[k] *= scale
    for k in ("load", "hold"):
        c[k] *= math.sqrt(scale)
    return c


def capstan_threshold(r, l1, l2):
    """mu* at which the heavy rope just holds (bisection on T(pi R) = w l2)."""
    lo, hi = 0.0, 5.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if capstan_tension(mid, r, 1.0, l1) < l2:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


if __name__ == "__main__":
    print("chain period", chain_period())
    print("mu*(0.1, 0.1, 0.3) =", capstan_threshold(0.1, 0.1, 0.3))
    print("mu*(1e-4, 0.1, 0.3) =", capstan_threshold(1e-4, 0.1, 0.3), math.log(3) / math.pi)


def preset(name):
    """A yarn preset's tex (g/km), diameter (m), EA (N), EI (N m^2) and
    friction on yarn and on solids, as `yarnsim materials` lists them (the
    one table: `src/scene/yarn/presets.rs`)."""
    import subprocess

    from yarnsim_rope import CLI
    out = subprocess.run([CLI, "materials"], check=True, capture_output=True, text=True).stdout
    for line in out.splitlines():
        f = line.split()
        if f and f[0] == name:
            return dict(tex=float(f[1]), diameter=float(f[2]) * 1e-3, ea=float(f[3]),
                        ei=float(f[4]), friction=float(f[5]), friction_solid=float(f[6]))
    raise KeyError(f"no preset {name!r} in `yarnsim materials`")


def preset_bundle(name):
    """The reference bundle's `BUNDLE` overrides for one real yarn of
    preset `name` per rope: line density tex 1e-6 kg/m (yarnsim's
    `density = tex 1e-6 / s` per metre of depth is 1 / s such yarns, so
    one yarn is the sheet's mass times s), bending EI and the yarn-on-yarn
    friction of the preset; the circles keep the scene's 0.3."""
    p = preset(name)
    return dict(rho=p["tex"] * 1e-6, bending=p["ei"], yarn_friction=p["friction"])


def hanging_beam_omegas(segments, line_density, bending, length=CHAIN["length"], g=CHAIN["g"]):
    """The lowest transverse angular frequencies of a hanging heavy rod
    with bending rigidity `bending` (the string's tension mu g (L - s) and
    EI times the fourth derivative), pinned without a moment at the top,
    free at the bottom: `segments` equal segments, lumped masses (half at
    the free end), the string energy T dw^2 / (2 l) per segment and
    EI (d2w)^2 / (2 l^3) per interior vertex; scipy's generalized
    symmetric eigensolver."""
    import numpy as np
    from scipy.linalg import eigh
    n, l = segments, length / segments
    k = np.zeros((n + 1, n + 1))
    for j in range(n):
        a = line_density * g * (length - (j + 0.5) * l) / l
        k[j:j + 2, j:j + 2] += a * np.array([[1.0, -1.0], [-1.0, 1.0]])
    c = bending / l ** 3
    v = np.array([1.0, -2.0, 1.0])
    for i in range(1, n):
        k[i - 1:i + 2, i - 1:i + 2] += c * np.outer(v, v)
    m = np.full(n + 1, line_density * l)
    m[-1] *= 0.5
    w2 = eigh(k[1:, 1:], np.diag(m[1:]), eigvals_only=True, subset_by_index=[0, 1])
    return np.sqrt(w2)


def hanging_beam_period(line_density, bending):
    """The hanging rod's first-mode period (s), Richardson-extrapolated
    from 400 and 800 segments (the discretisation error is second order:
    without bending it gives `chain_period` within 1e-8)."""
    p400 = 2 * math.pi / hanging_beam_omegas(400, line_density, bending)[0]
    p800 = 2 * math.pi / hanging_beam_omegas(800, line_density, bending)[0]
    return (4 * p800 - p400) / 3


def preset_chain(name):
    """The hanging chain as one real yarn of preset `name`: EA (`k`), line
    density tex 1e-6 kg/m (`rho`), EI (`bending`) and the
    hanging rod's first-mode period (`oracle`, bending included)."""
    p = preset(name)
    rho = p["tex"] * 1e-6
    return dict(k=p["ea"], rho=rho, bending=p["ei"],
                oracle=hanging_beam_period(rho, p["ei"]))
