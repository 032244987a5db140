"""A log-log work-precision plot (|error| against wall seconds per
simulated second) as a plain SVG, one line per tool, integrator and case."""

import math

COLORS = {"yarnsim": "#1f77b4", "mujoco": "#d62728", "pyelastica": "#2ca02c"}
# a tool's other integrators (by (tool, integrator)); default: COLORS[tool]
INTEGRATOR_COLORS = {("yarnsim", "mpm-implicit"): "#9467bd",
                     ("yarnsim", "mpm-implicit-k2e5"): "#ff7f0e",
                     ("yarnsim", "vertices-implicit"): "#8c564b",
                     ("yarnsim", "vertices-midpoint"): "#e377c2",
                     ("yarnsim", "mpm-axial-implicit"): "#17becf"}
# the single-yarn cases (the bundles have no oracle: not drawn)
DASH = {"chain": "", "cantilever": "6,3", "capstan": "2,2", "chain-nylon": "10,3,2,3",
        "capstan-nylon": "10,3,2,3"}
MARK = {"chain": "circle", "cantilever": "square", "capstan": "diamond",
        "chain-nylon": "circle", "capstan-nylon": "diamond"}


def _ticks(lo, hi):
    return [10.0 ** k for k in range(math.floor(lo), math.ceil(hi) + 1)]


def work_precision(rows, path, title):
    pts = [r for r in rows if r["ok"] and r["case"] in DASH
           and math.isfinite(r["error"]) and r["error"] != 0
           and math.isfinite(r["wall_s_per_sim_s"]) and r["wall_s_per_sim_s"] > 0]
    W, H, ml, mr, mt, mb = 900, 520, 80, 300, 40, 60
    if not pts:
        open(path, "w").write(f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" '
                              f'height="{H}"><text x="20" y="40">no data</text></svg>\n')
        return
    lx = [math.log10(r["wall_s_per_sim_s"]) for r in pts]
    ly = [math.log10(abs(r["error"])) for r in pts]
    x0, x1 = math.floor(min(lx)), math.ceil(max(lx))
    y0, y1 = math.floor(min(ly)), math.ceil(max(ly))
    x1, y1 = max(x1, x0 + 1), max(y1, y0 + 1)

    def X(v):
        return ml + (math.log10(v) - x0) / (x1 - x0) * (W - ml - mr)

    def Y(v):
        return H - mb - (math.log10(v) - y0) / (y1 - y0) * (H - mt - mb)

    s = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" '
         f'font-family="sans-serif" font-size="12">',
         f'<rect width="{W}" height="{H}" fill="white"/>',
         f'<text x="{ml}" y="22" font-size="14">{title}</text>']
    for t in _ticks(x0, x1):
        s.append(f'<line x1="{X(t):.1f}" y1="{mt}" x2="{X(t):.1f}" y2="{H - mb}" stroke="#ddd"/>')
        s.append(f'<text x="{X(t):.1f}" y="{H - mb + 16}" text-anchor="middle">{t:g}</text>')
    for t in _ticks(y0, y1):
        s.append(f'<line x1="{ml}" y1="{Y(t):.1f}" x2="{W - mr}" y2="{Y(t):.1f}" stroke="#ddd"/>')
        s.append(f'<text x="{ml - 6}" y="{Y(t) + 4:.1f}" text-anchor="end">{t:g}</text>')
    s.append(f'<rect x="{ml}" y="{mt}" width="{W - ml - mr}" height="{H - mt - mb}" '
             f'fill="none" stroke="black"/>')
    s.append(f'<text x="{(ml + W - mr) / 2}" y="{H - 18}" text-anchor="middle">wall seconds per '
             f'simulated second (one thread, stepping loop)</text>')
    s.append(f'<text transform="translate(20,{(mt + H - mb) / 2}) rotate(-90)" '
             f'text-anchor="middle">|relative error| against the analytic oracle</text>')
    groups = {}
    for r in pts:
        groups.setdefault((r["tool"], r["integrator"], r["case"]), []).append(r)
    ly_leg = mt + 10
    for (tool, integ, case), rs in sorted(groups.items()):
        rs = sorted(rs, key=lambda r: r["wall_s_per_sim_s"])
        col = INTEGRATOR_COLORS.get((tool, integ), COLORS.get(tool, "black"))
        xy = [(X(r["wall_s_per_sim_s"]), Y(abs(r["error"]))) for r in rs]
        if len(xy) > 1:
            d = " ".join(f"{x:.1f},{y:.1f}" for x, y in xy)
            s.append(f'<polyline points="{d}" fill="none" stroke="{col}" stroke-width="1.5" '
                     f'stroke-dasharray="{DASH[case]}"/>')
        for (x, y), r in zip(xy, rs):
            fill = col if r["error"] > 0 else "white"
            if MARK[case] == "circle":
                s.append(f'<circle cx="{x:.1f}" cy="{y:.1f}" r="4" fill="{fill}" stroke="{col}"/>')
            elif MARK[case] == "square":
                s.append(f'<rect x="{x - 4:.1f}" y="{y - 4:.1f}" width="8" height="8" '
                         f'fill="{fill}" stroke="{col}"/>')
            else:
                s.append(f'<polygon points="{x:.1f},{y - 5:.1f} {x + 5:.1f},{y:.1f} '
                         f'{x:.1f},{y + 5:.1f} {x - 5:.1f},{y:.1f}" fill="{fill}" '
                         f'stroke="{col}"/>')
        lx0 = W - mr + 12
        s.append(f'<line x1="{lx0}" y1="{ly_leg}" x2="{lx0 + 24}" y2="{ly_leg}" stroke="{col}" '
                 f'stroke-width="1.5" stroke-dasharray="{DASH[case]}"/>')
        s.append(f'<text x="{lx0 + 30}" y="{ly_leg + 4}">{tool} {integ}, {case}</text>')
        ly_leg += 18
    s.append(f'<text x="{W - mr + 12}" y="{ly_leg + 10}" font-size="10">filled: error &gt; 0, '
             f'open: &lt; 0</text>')
    s.append("</svg>")
    open(path, "w").write("\n".join(s) + "\n")
