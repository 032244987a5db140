//! The implicit (backward Euler) grid update of a yarn scene whose energy
//! is pure fibre stretch (`gamma = 0`, `youngs_modulus = 0`, `bending = 0`,
//! no plasticity): the optimization form of Gast, Schroeder, Stomakhin,
//! Jiang, Teran 2015, "Optimization integrator for large time steps"
//! (IEEE TVCG 21(10)). The new grid velocities `v` minimise
//!
//! ```text
//! E(v) = sum_i m_i |v_i - v*_i|^2 / 2 + Psi(x(v)),   x_p(v) = x_p + dt sum_i w_ip v_i
//! Psi  = sum_q vol_q k / 2 (|x_r - x_l| / l0_q - 1)^2
//! ```
//!
//! with `v*` the scattered momentum over mass plus `dt g` and `w_ip` the
//! start-of-step weights of the vertices. `Psi` is the explicit model's own
//! energy at `gamma = E = 0` ([`super::constitutive`]: `psi = k/2 (r11 -
//! 1)^2` with `r11 = |d1| / l0`, `d1 = x_r - x_l`), so both integrators
//! model the same material. Its gradient and its exact Hessian (the
//! standard spring Hessian `c [u u^T + (1 - l0/L)(I - u u^T)]`,
//! `c = vol k / l0^2`) are analytic; [`Problem::hess_vec`] is the
//! matrix-free `H d = M d + dt^2 W^T K W d`. Fixed pins are linear
//! constraints `sum_i w_ip v_i = target` on the grid (the explicit step's
//! constraint, [`super::pins::constrain_grid`], solved exactly here), held
//! by the mass-weighted projection [`Problem::project`]. The solver is in
//! [`newton`].

pub mod newton;
pub mod precond;
#[cfg(test)]
mod tests;

use super::grid::{Grid, VX, VY};
use super::particles::{Particles, NONE};
use super::pins::PinEntry;
use crate::math::Vec2;

pub use newton::{solve, Precond, Settings, Solution, SolveStats};

/// One vertex's 3x3 stencil in unknown indices ([`NONE`]: a node without
/// mass, weight 0).
#[derive(Clone, Copy, Debug)]
struct Weights {
    node: [u32; 9],
    w: [f64; 9],
}

/// One fibre segment: left vertex (the right one is `left + 1`), rest
/// length and stiffness `c = vol k / l0^2` (`psi = c/2 (L - l0)^2`).
#[derive(Clone, Copy, Debug)]
struct Spring {
    left: usize,
    l0: f64,
    c: f64,
}

/// The minimisation of one implicit substep on the active grid nodes.
#[derive(Clone, Debug)]
pub struct Problem {
    /// Window index of each unknown node.
    pub nodes: Vec<usize>,
    /// Node masses.
    pub mass: Vec<f64>,
    /// `v*`: momentum over mass plus `dt g`.
    pub vstar: Vec<Vec2>,
    dt: f64,
    x0: Vec<Vec2>,
    weights: Vec<Weights>,
    springs: Vec<Spring>,
    /// Pin constraint rows (weights in unknown indices) and targets.
    rows: Vec<(Weights, Vec2, usize)>,
    /// Cholesky factor (lower, row-major) of `S = A M^-1 A^T`.
    chol: Vec<f64>,
}

impl Problem {
    /// Collects the unknowns from the scatter: call after the scatter and
    /// before the grid update (which consumes the buffers the masses are
    /// read from). `k` the fibre stiffness. `v*` is read later
    /// ([`Problem::read_vstar`]).
    pub fn collect(p: &Particles, grid: &Grid, k: f64, dt: f64, pins: &[PinEntry]) -> Self {
        let geom = grid.geom;
        let mut map = vec![NONE; geom.storage()];
        let mut nodes = Vec::new();
        let mut mass = Vec::new();
        let mut node_of = |idx: usize, ni: usize, nj: usize| -> u32 {
            if map[idx] == NONE {
                let m = grid.scattered_mass(idx, ni, nj);
                if m <= 0.0 {
                    return NONE;
                }
                map[idx] = nodes.len() as u32;
                nodes.push(idx);
                mass.push(m);
            }
            map[idx]
        };
        let mut weights = Vec::with_capacity(p.vert.x.len());
        for st in &p.vert.stencil {
            let (bi, bj) = (st.base[0] as usize, st.base[1] as usize);
            let mut w = Weights {
                node: [NONE; 9],
                w: [0.0; 9],
            };
            for a in 0..3 {
                for b in 0..3 {
                    let n = 3 * a + b;
                    let (ni, nj) = (bi + a, bj + b);
                    w.node[n] = node_of(geom.index(ni, nj), ni, nj);
                    if w.node[n] != NONE {
                        w.w[n] = st.weight(a, b);
                    }
                }
            }
            weights.push(w);
        }
        // the quadrature particles' nodes carry mass too (no energy)
        for st in &p.quad.stencil {
            let (bi, bj) = (st.base[0] as usize, st.base[1] as usize);
            for a in 0..3 {
                for b in 0..3 {
                    let (ni, nj) = (bi + a, bj + b);
                    node_of(geom.index(ni, nj), ni, nj);
                }
            }
        }
        let q = &p.quad;
        let springs = (0..q.l0.len())
            .map(|i| Spring {
                left: q.left[i] as usize,
                l0: q.l0[i],
                c: q.vol[i] * k / (q.l0[i] * q.l0[i]),
            })
            .collect();
        let rows = pins
            .iter()
            .map(|e| {
                let mut w = Weights {
                    node: [NONE; 9],
                    w: [0.0; 9],
                };
                for n in 0..9 {
                    let u = map[e.idx[n]];
                    if u != NONE {
                        w.node[n] = u;
                        w.w[n] = e.w[n];
                    }
                }
                (w, e.target, e.pin)
            })
            .collect();
        let vstar = vec![Vec2::zeros(); nodes.len()];
        let mut prob = Problem {
            nodes,
            mass,
            vstar,
            dt,
            x0: p.vert.x.clone(),
            weights,
            springs,
            rows,
            chol: Vec::new(),
        };
        prob.factor();
        prob
    }

    /// Reads `v*` from the grid after the grid update.
    pub fn read_vstar(&mut self, grid: &Grid) {
        for (v, &idx) in self.vstar.iter_mut().zip(&self.nodes) {
            let n = grid.node[idx];
            *v = Vec2::new(n[VX], n[VY]);
        }
    }

    /// The substep.
    pub fn dt(&self) -> f64 {
        self.dt
    }
    /// `|F|`, `F` the segments' forces at 100 % strain (`c l0` each).
    pub fn force_scale(&self) -> f64 {
        self.springs
            .iter()
            .map(|s| (s.c * s.l0).powi(2))
            .sum::<f64>()
            .sqrt()
    }
    /// Number of unknown nodes.
    pub fn len(&self) -> usize {
        self.nodes.len()
    }
    /// Whether there are no unknowns.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// Vertex positions at the end of the substep for grid velocities `v`.
    pub fn positions(&self, v: &[Vec2]) -> Vec<Vec2> {
        let mut x = self.x0.clone();
        for (x, w) in x.iter_mut().zip(&self.weights) {
            *x += interp(w, v) * self.dt;
        }
        x
    }

    /// `E(v)`.
    pub fn energy(&self, v: &[Vec2]) -> f64 {
        let kinetic: f64 = (0..v.len())
            .map(|i| 0.5 * self.mass[i] * (v[i] - self.vstar[i]).norm_squared())
            .sum();
        let x = self.positions(v);
        let elastic: f64 = self
            .springs
            .iter()
            .map(|s| {
                let l = (x[s.left + 1] - x[s.left]).norm();
                0.5 * s.c * (l - s.l0) * (l - s.l0)
            })
            .sum();
        kinetic + elastic
    }

    /// `dE/dv = M (v - v*) + dt W^T dPsi/dx`.
    pub fn gradient(&self, v: &[Vec2]) -> Vec<Vec2> {
        let x = self.positions(v);
        let mut gx = vec![Vec2::zeros(); x.len()];
        for s in &self.springs {
            let e = x[s.left + 1] - x[s.left];
            let l = e.norm();
            if l > 0.0 {
                let f = e * (s.c * (l - s.l0) / l);
                gx[s.left + 1] += f;
                gx[s.left] -= f;
            }
        }
        let mut g: Vec<Vec2> = (0..v.len())
            .map(|i| (v[i] - self.vstar[i]) * self.mass[i])
            .collect();
        self.scatter_to(&gx, self.dt, &mut g);
        g
    }

    /// `H d = M d + dt^2 W^T K W d` at `v`, `K` the exact Hessian of `Psi`.
    pub fn hess_vec(&self, v: &[Vec2], d: &[Vec2]) -> Vec<Vec2> {
        let x = self.positions(v);
        let dx: Vec<Vec2> = self.weights.iter().map(|w| interp(w, d)).collect();
        let mut kx = vec![Vec2::zeros(); x.len()];
        for (s, u, l) in self.segments(&x) {
            let de = dx[s.left + 1] - dx[s.left];
            let along = u * u.dot(&de);
            let f = (along + (de - along) * (1.0 - s.l0 / l)) * s.c;
            kx[s.left + 1] += f;
            kx[s.left] -= f;
        }
        let mut y: Vec<Vec2> = (0..d.len()).map(|i| d[i] * self.mass[i]).collect();
        self.scatter_to(&kx, self.dt * self.dt, &mut y);
        y
    }

    /// Diagonal of `H` at `v` per component, with each spring's transverse
    /// term clamped at 0 (the Jacobi preconditioner must be positive).
    pub fn diagonal(&self, v: &[Vec2]) -> Vec<Vec2> {
        let x = self.positions(v);
        let mut kd = vec![Vec2::zeros(); x.len()];
        for (s, u, l) in self.segments(&x) {
            let t = (1.0 - s.l0 / l).max(0.0);
            let k = Vec2::new(
                u.x * u.x + t * (1.0 - u.x * u.x),
                u.y * u.y + t * (1.0 - u.y * u.y),
            ) * s.c;
            kd[s.left] += k;
            kd[s.left + 1] += k;
        }
        let dt2 = self.dt * self.dt;
        let mut out: Vec<Vec2> = self.mass.iter().map(|&m| Vec2::new(m, m)).collect();
        for (w, k) in self.weights.iter().zip(&kd) {
            for n in 0..9 {
                if w.node[n] != NONE {
                    out[w.node[n] as usize] += k * (dt2 * w.w[n] * w.w[n]);
                }
            }
        }
        out
    }

    /// The stiff rows of the fibre stretch at `v` for [`precond`]: per
    /// segment `b_n = dt (w_right,n - w_left,n) u` and `c`, grouped by yarn.
    pub fn stiff_rows(&self, v: &[Vec2]) -> Vec<precond::StiffRow> {
        let x = self.positions(v);
        let mut rows = Vec::with_capacity(self.springs.len());
        let mut group = 0u32;
        let mut prev: Option<usize> = None;
        for s in &self.springs {
            if prev.is_some_and(|p| p + 1 != s.left) {
                group += 1;
            }
            prev = Some(s.left);
            let e = x[s.left + 1] - x[s.left];
            let l = e.norm();
            if l <= 0.0 {
                continue;
            }
            let u = e / l;
            let mut entries: Vec<(u32, Vec2)> = Vec::with_capacity(18);
            for (w, sign) in [
                (&self.weights[s.left + 1], 1.0),
                (&self.weights[s.left], -1.0),
            ] {
                for n in 0..9 {
                    if w.node[n] == NONE {
                        continue;
                    }
                    let c = u * (sign * self.dt * w.w[n]);
                    match entries.iter_mut().find(|(i, _)| *i == w.node[n]) {
                        Some(e) => e.1 += c,
                        None => entries.push((w.node[n], c)),
                    }
                }
            }
            rows.push(precond::StiffRow {
                group,
                entries,
                c: s.c,
            });
        }
        rows
    }

    /// [`Problem::diagonal`] without the segments' axial part (what
    /// [`Problem::stiff_rows`] carries).
    pub fn diagonal_rest(&self, v: &[Vec2]) -> Vec<Vec2> {
        let x = self.positions(v);
        let mut kd = vec![Vec2::zeros(); x.len()];
        for (s, u, l) in self.segments(&x) {
            let t = (1.0 - s.l0 / l).max(0.0);
            let k = Vec2::new(t * (1.0 - u.x * u.x), t * (1.0 - u.y * u.y)) * s.c;
            kd[s.left] += k;
            kd[s.left + 1] += k;
        }
        let dt2 = self.dt * self.dt;
        let mut out: Vec<Vec2> = self.mass.iter().map(|&m| Vec2::new(m, m)).collect();
        for (w, k) in self.weights.iter().zip(&kd) {
            for n in 0..9 {
                if w.node[n] != NONE {
                    out[w.node[n] as usize] += k * (dt2 * w.w[n] * w.w[n]);
                }
            }
        }
        out
    }

    /// Each segment of non-zero length at the positions `x`, with its unit
    /// direction `u` and length `L`.
    fn segments<'a>(&'a self, x: &'a [Vec2]) -> impl Iterator<Item = (&'a Spring, Vec2, f64)> + 'a {
        self.springs.iter().filter_map(|s| {
            let e = x[s.left + 1] - x[s.left];
            let l = e.norm();
            (l > 0.0).then(|| (s, e / l, l))
        })
    }

    /// `out += s W^T f` (vertex vectors `f` to the nodes).
    fn scatter_to(&self, f: &[Vec2], s: f64, out: &mut [Vec2]) {
        for (w, f) in self.weights.iter().zip(f) {
            for n in 0..9 {
                if w.node[n] != NONE {
                    out[w.node[n] as usize] += f * (s * w.w[n]);
                }
            }
        }
    }

    /// Factors `S = A M^-1 A^T` of the pin rows (dense Cholesky; the pins
    /// of a scene are a few vertices).
    fn factor(&mut self) {
        let n = self.rows.len();
        let mut s = vec![0.0; n * n];
        for a in 0..n {
            for b in 0..=a {
                let (ra, rb) = (&self.rows[a].0, &self.rows[b].0);
                let mut sum = 0.0;
                for i in 0..9 {
                    for j in 0..9 {
                        if ra.node[i] != NONE && ra.node[i] == rb.node[j] {
                            sum += ra.w[i] * rb.w[j] / self.mass[ra.node[i] as usize];
                        }
                    }
                }
                s[a * n + b] = sum;
            }
        }
        for j in 0..n {
            let mut d = s[j * n + j];
            for k in 0..j {
                d -= s[j * n + k] * s[j * n + k];
            }
            let d = d.max(1e-300).sqrt();
            s[j * n + j] = d;
            for i in j + 1..n {
                let mut v = s[i * n + j];
                for k in 0..j {
                    v -= s[i * n + k] * s[j * n + k];
                }
                s[i * n + j] = v / d;
            }
        }
        self.chol = s;
    }

    /// `S^-1 b` per component.
    fn solve_s(&self, b: &mut [Vec2]) {
        let (n, l) = (self.rows.len(), &self.chol);
        for i in 0..n {
            for k in 0..i {
                let t = b[k] * l[i * n + k];
                b[i] -= t;
            }
            b[i] /= l[i * n + i];
        }
        for i in (0..n).rev() {
            for k in i + 1..n {
                let t = b[k] * l[k * n + i];
                b[i] -= t;
            }
            b[i] /= l[i * n + i];
        }
    }

    /// `A x` (each pinned vertex's interpolated value).
    fn apply_a(&self, x: &[Vec2]) -> Vec<Vec2> {
        self.rows.iter().map(|(w, _, _)| interp(w, x)).collect()
    }

    /// `out += A^T l`, each term scaled by `1/m` when `inv_m`.
    fn add_at(&self, l: &[Vec2], inv_m: bool, out: &mut [Vec2]) {
        for ((w, _, _), l) in self.rows.iter().zip(l) {
            for n in 0..9 {
                if w.node[n] != NONE {
                    let i = w.node[n] as usize;
                    let s = if inv_m { w.w[n] / self.mass[i] } else { w.w[n] };
                    out[i] += l * s;
                }
            }
        }
    }

    /// The feasible point nearest to `v` in the mass norm: every pinned
    /// vertex's interpolated velocity at its target.
    pub fn make_feasible(&self, v: &mut [Vec2]) {
        if self.rows.is_empty() {
            return;
        }
        let mut r: Vec<Vec2> = self.apply_a(v);
        for (r, (_, t, _)) in r.iter_mut().zip(&self.rows) {
            *r = t - *r;
        }
        self.solve_s(&mut r);
        self.add_at(&r, true, v);
    }

    /// `Pi x = x - M^-1 A^T S^-1 A x`: onto the velocity changes that keep
    /// the pins (mass-orthogonal projection).
    pub fn project(&self, x: &mut [Vec2]) {
        if self.rows.is_empty() {
            return;
        }
        let mut l = self.apply_a(x);
        self.solve_s(&mut l);
        l.iter_mut().for_each(|l| *l = -*l);
        self.add_at(&l, true, x);
    }

    /// `Pi^T g = g - A^T S^-1 A M^-1 g`, and the multipliers
    /// `S^-1 A M^-1 g` (each pinned vertex's impulse on the grid at the
    /// solution).
    pub fn project_dual(&self, g: &mut [Vec2]) -> Vec<Vec2> {
        if self.rows.is_empty() {
            return Vec::new();
        }
        let gm: Vec<Vec2> = g.iter().zip(&self.mass).map(|(g, m)| g / *m).collect();
        let mut l = self.apply_a(&gm);
        self.solve_s(&mut l);
        let neg: Vec<Vec2> = l.iter().map(|l| -l).collect();
        self.add_at(&neg, false, g);
        l
    }

    /// Whether any pin constrains the grid.
    pub fn has_pins(&self) -> bool {
        !self.rows.is_empty()
    }

    /// Pin index of each constraint row.
    pub fn row_pins(&self) -> impl Iterator<Item = usize> + '_ {
        self.rows.iter().map(|r| r.2)
    }
}

/// `sum_i w_i v_i` over a stencil.
#[inline]
fn interp(w: &Weights, v: &[Vec2]) -> Vec2 {
    let mut s = Vec2::zeros();
    for n in 0..9 {
        if w.node[n] != NONE {
            s += v[w.node[n] as usize] * w.w[n];
        }
    }
    s
}

/// `sum a_i . b_i`.
pub fn dot(a: &[Vec2], b: &[Vec2]) -> f64 {
    a.iter().zip(b).map(|(a, b)| a.dot(b)).sum()
}
