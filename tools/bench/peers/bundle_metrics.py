"""What a bundle run did, from every yarn's vertex positions (yarnsim's
plane: x right, y up), the same measures for every tool."""

import numpy as np


def _crossings(a, b):
    """Proper intersections between the segments of polylines a and b."""
    p, r = a[:-1, None, :], (a[1:] - a[:-1])[:, None, :]
    q, s = b[None, :-1, :], (b[1:] - b[:-1])[None, :, :]
    rxs = r[..., 0] * s[..., 1] - r[..., 1] * s[..., 0]
    qp = q - p
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (qp[..., 0] * s[..., 1] - qp[..., 1] * s[..., 0]) / rxs
        u = (qp[..., 0] * r[..., 1] - qp[..., 1] * r[..., 0]) / rxs
    return int(np.sum((rxs != 0) & (t > 0) & (t < 1) & (u > 0) & (u < 1)))


def measures(yarns, b):
    rest = b["length"] / (b["vertices"] - 1)
    allx = np.concatenate(yarns)
    stretch = np.concatenate([np.linalg.norm(np.diff(y, axis=0), axis=1) / rest for y in yarns])
    depth = max(float(np.max(b["cyl_radius"] - np.linalg.norm(allx - np.array(c), axis=1)))
                for c in b["cylinders"])
    touching = sum(
        1 for y in yarns
        if min(np.min(np.linalg.norm(y - np.array(c), axis=1)) for c in b["cylinders"])
        < b["cyl_radius"] + 0.01)
    cross = sum(_crossings(yarns[i], yarns[j])
                for i in range(len(yarns)) for j in range(i + 1, len(yarns)))
    return dict(min_y=float(allx[:, 1].min()), mean_y=float(allx[:, 1].mean()),
                touching=touching, crossings=cross, depth=depth,
                stretch=(float(stretch.min()), float(stretch.max())))


def describe(yarns, b):
    m = measures(yarns, b)
    pen = (f"deepest vertex {m['depth'] * 1e3:.2f} mm inside a cylinder" if m["depth"] > 0
           else "no vertex inside a cylinder")
    return (f"{m['touching']}/{len(yarns)} yarns within 1 cm of a cylinder; mean height "
            f"{m['mean_y']:.3f} m, lowest {m['min_y']:.3f} m; {m['crossings']} yarn-yarn "
            f"segment crossings; {pen}; stretch {m['stretch'][0]:.3f}..{m['stretch'][1]:.3f}")


def centre_of_mass(yarns):
    """The centre of mass of uniform polylines of equal mass per length and
    equal rest lengths (each vertex the mass of its segment halves: the
    ends half an interior vertex), as yarnsim's and MuJoCo's yarns are."""
    w = np.ones(len(yarns[0]))
    w[[0, -1]] = 0.5
    return np.mean([np.average(y, axis=0, weights=w) for y in yarns], axis=0)


def frame_distances(fa, fb):
    """Between two runs' frames ([time, yarns] lists, matched by time
    within 1e-6 s): the largest distance of the centres of mass and of
    any yarn end (m) over the matched frames, and those at the last one;
    the matched count."""
    tb = {round(t, 6): ys for t, ys in fb}
    com, ends, n = [], [], 0
    for t, ya in fa:
        yb = tb.get(round(t, 6))
        if yb is None:
            continue
        n += 1
        com.append(float(np.linalg.norm(centre_of_mass(ya) - centre_of_mass(yb))))
        ends.append(max(float(np.linalg.norm(a[k] - b[k])) for a, b in zip(ya, yb)
                        for k in (0, -1)))
    if not n:
        return None
    return dict(com_max=max(com), ends_max=max(ends), com_end=com[-1], ends_end=ends[-1],
                frames=n)
