//! The unknowns of one implicit substep and the energy's sparse affine
//! maps from them: per quadrature particle the merged list of `(node, c1,
//! c2)` with `d1(v) = d1_0 + sum c1_n v_n`, `d2(v) = d2_old + sum c2_n
//! v_n`; per bending vertex the merged list of `(node, a1, a2)` with the
//! edges `e1(v) = e1_0 + sum a1_n v_n`, `e2(v) = e2_0 + sum a2_n v_n`
//! (`a1 = c_j - c_prev`, `a2 = c_next - c_j` from the vertices' stencils:
//! the energy depends on the edges only, so the block is 4x4 without the
//! translation modes); per node its position for the attractor.

// small dense blocks and stencils: index loops read as the formulas
#![allow(clippy::needless_range_loop)]

use super::Problem;
use crate::math::bspline::Stencil;
use crate::math::Vec2;
use crate::mpm::laws::constitutive::YarnEnergy;
use crate::mpm::laws::pins::PinEntry;
use crate::mpm::machinery::grid::{Grid, VX, VY};
use crate::mpm::machinery::particles::{Particles, NONE};

/// One stencil in unknown indices ([`NONE`]: a node without mass, weight 0).
#[derive(Clone, Copy, Debug)]
pub(super) struct Weights {
    pub node: [u32; 9],
    pub w: [f64; 9],
}

/// One quadrature particle: rest length, volume, `d1` and `d2` at `v = 0`
/// and its terms `quad_terms[start..end]`.
#[derive(Clone, Copy, Debug)]
pub(super) struct QuadElem {
    /// Left vertex (segments of one yarn have consecutive ones).
    pub left: u32,
    pub l0: f64,
    pub vol: f64,
    pub d1: Vec2,
    pub d2: Vec2,
    pub start: u32,
    pub end: u32,
}

/// `(node, c1, c2)`: the node's velocity moves `d1` by `c1 v_n` and `d2`
/// by `c2 v_n`.
#[derive(Clone, Copy, Debug)]
pub(super) struct QuadTerm {
    pub node: u32,
    pub c1: f64,
    pub c2: f64,
}

/// One interior vertex's bending: rest curvature, `1 / l`, the edges
/// `(e1, e2)` at `v = 0` and its terms `bend_terms[start..end]`.
#[derive(Clone, Copy, Debug)]
pub(super) struct BendElem {
    pub kappa0: f64,
    pub inv_len: f64,
    pub e: [Vec2; 2],
    pub start: u32,
    pub end: u32,
}

/// `(node, a)`: the node's velocity moves edge `k` of the vertex by
/// `a[k] v_n`.
#[derive(Clone, Copy, Debug)]
pub(super) struct BendTerm {
    pub node: u32,
    pub a: [f64; 2],
}

/// The attractor's node energy `m_i phi(|x_i + dt v_i - p|)`,
/// `phi(r) = s (r - 0.01 ln(r + 0.01))`.
#[derive(Clone, Debug)]
pub(super) struct AttractorTerm {
    pub position: Vec2,
    pub strength: f64,
    /// Each unknown node's position.
    pub x: Vec<Vec2>,
}

/// The normal law of an obstacle on one unknown node as an energy,
/// `w / 2 min(v . n, 0)^2` (`n` the outward normal, `w = c m` with `c =
/// share / (1 - share)`, capped): alone with the node's kinetic term
/// `m / 2 |v - v*|^2` its minimiser is the explicit law's
/// (`crate::mpm::laws::contact::obstacle_normal`: the inward normal velocity
/// of the touching share removed, `v . n = (1 - share) v* . n`), and its
/// normal impulse `w max(-v . n, 0)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactTerm {
    /// Unknown index of the node.
    pub node: u32,
    /// Outward unit normal.
    pub n: Vec2,
    /// `w = c m`, kg.
    pub w: f64,
}

/// A problem's elements: the quadrature particles' and the bent vertices',
/// each with its node terms.
pub(super) struct Elements {
    pub(super) quads: Vec<QuadElem>,
    pub(super) quad_terms: Vec<QuadTerm>,
    pub(super) bends: Vec<BendElem>,
    pub(super) bend_terms: Vec<BendTerm>,
}

/// The energy the implicit step minimises, as the substep passes it.
#[derive(Clone, Copy, Debug)]
pub struct Model {
    pub energy: YarnEnergy,
    /// Bending stiffness `B` (0: none).
    pub bending: f64,
    /// `(position, strength)` when the attractor acts.
    pub attractor: Option<(Vec2, f64)>,
}

/// Merges `(node, c)` into a list kept in first-seen order.
fn merge<const N: usize>(list: &mut Vec<(u32, [f64; N])>, node: u32, k: usize, c: f64) {
    if let Some(e) = list.iter_mut().find(|e| e.0 == node) {
        e.1[k] += c;
    } else {
        let mut a = [0.0; N];
        a[k] = c;
        list.push((node, a));
    }
}

impl Problem {
    /// Collects the unknowns from the scatter: call after the scatter and
    /// before the grid update (which consumes the buffers the masses are
    /// read from). `v*` is read later ([`Problem::read_vstar`]).
    pub fn collect(p: &Particles, grid: &Grid, model: &Model, dt: f64, pins: &[PinEntry]) -> Self {
        Self::collect_field(p, grid, model, dt, pins, None)
    }

    /// [`Problem::collect`] of one velocity field of a scene with several
    /// ([`crate::mpm::laws::fields`]): `only = Some((vert_field,
    /// quad_field, k))` keeps the vertices and quadrature particles of
    /// field `k` (their grid is `grid`); the others are no part of this
    /// problem (the energy has no element across the fields: a yarn is
    /// wholly in one).
    pub fn collect_field(
        p: &Particles,
        grid: &Grid,
        model: &Model,
        dt: f64,
        pins: &[PinEntry],
        only: Option<(&[u16], &[u16], u16)>,
    ) -> Self {
        let keep_vert = |i: usize| only.is_none_or(|(v, _, h)| v[i] == h);
        let keep_quad = |i: usize| only.is_none_or(|(_, q, h)| q[i] == h);
        let geom = grid.geom;
        let mut map = vec![NONE; geom.storage()];
        let mut nodes = Vec::new();
        let mut mass = Vec::new();
        let mut node_x = Vec::new();
        let mut node_of = |idx: usize, ni: usize, nj: usize| -> u32 {
            if map[idx] == NONE {
                let m = grid.scattered_mass(idx, ni, nj);
                if m <= 0.0 {
                    return NONE;
                }
                map[idx] = nodes.len() as u32;
                nodes.push(idx);
                mass.push(m);
                node_x.push(Vec2::new(ni as f64, nj as f64) * geom.dx);
            }
            map[idx]
        };
        let mut stencil = |st: &Stencil| -> Weights {
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
            w
        };
        let none = Weights {
            node: [NONE; 9],
            w: [0.0; 9],
        };
        let vw: Vec<Weights> = (p.vert.stencil.iter().enumerate())
            .map(|(i, st)| if keep_vert(i) { stencil(st) } else { none })
            .collect();
        let qw: Vec<Weights> = (p.quad.stencil.iter().enumerate())
            .map(|(i, st)| if keep_quad(i) { stencil(st) } else { none })
            .collect();
        let (q, x) = (&p.quad, &p.vert.x);
        // c2 per unit of w (o . d2): dt 4 / dx (o = (x_n - x_q) / dx)
        let s2 = dt * 4.0 * geom.inv_dx;
        let mut quads = Vec::with_capacity(q.l0.len());
        let mut quad_terms = Vec::new();
        let mut list: Vec<(u32, [f64; 2])> = Vec::with_capacity(27);
        for k in (0..q.l0.len()).filter(|&k| keep_quad(k)) {
            list.clear();
            let l = q.left[k] as usize;
            let d2 = q.d[k].column(1).into_owned();
            for (side, sign) in [(l, -1.0), (l + 1, 1.0)] {
                let w = &vw[side];
                for n in 0..9 {
                    if w.node[n] != NONE {
                        merge(&mut list, w.node[n], 0, sign * dt * w.w[n]);
                    }
                }
            }
            let (w, st) = (&qw[k], &q.stencil[k]);
            for a in 0..3 {
                for b in 0..3 {
                    let n = 3 * a + b;
                    if w.node[n] != NONE {
                        merge(
                            &mut list,
                            w.node[n],
                            1,
                            s2 * w.w[n] * st.offset(a, b).dot(&d2),
                        );
                    }
                }
            }
            let start = quad_terms.len() as u32;
            quad_terms.extend(list.iter().map(|&(node, c)| QuadTerm {
                node,
                c1: c[0],
                c2: c[1],
            }));
            quads.push(QuadElem {
                left: l as u32,
                l0: q.l0[k],
                vol: q.vol[k],
                d1: x[l + 1] - x[l],
                d2,
                start,
                end: quad_terms.len() as u32,
            });
        }
        let mut bends = Vec::new();
        let mut bend_terms = Vec::new();
        if model.bending > 0.0 {
            let mut list: Vec<(u32, [f64; 3])> = Vec::with_capacity(27);
            for (j, rest) in p.vert.bend.iter().enumerate() {
                if rest.inv_len == 0.0 || !keep_vert(j) {
                    continue;
                }
                list.clear();
                for k in 0..3 {
                    let w = &vw[j + k - 1];
                    for n in 0..9 {
                        if w.node[n] != NONE {
                            merge(&mut list, w.node[n], k, dt * w.w[n]);
                        }
                    }
                }
                let start = bend_terms.len() as u32;
                bend_terms.extend(list.iter().filter_map(|&(node, c)| {
                    let a = [c[1] - c[0], c[2] - c[1]];
                    (a != [0.0; 2]).then_some(BendTerm { node, a })
                }));
                bends.push(BendElem {
                    kappa0: rest.kappa0,
                    inv_len: rest.inv_len,
                    e: [x[j] - x[j - 1], x[j + 1] - x[j]],
                    start,
                    end: bend_terms.len() as u32,
                });
            }
        }
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
        let elements = Elements {
            quads,
            quad_terms,
            bends,
            bend_terms,
        };
        Problem::assemble(nodes, mass, dt, model, node_x, elements, rows)
    }

    /// The problem of `elements` on `nodes` (masses `mass`, node positions
    /// `node_x` for the attractor), `v*` zero until it is read, no
    /// contacts, its pin rows factored.
    pub(super) fn assemble(
        nodes: Vec<usize>,
        mass: Vec<f64>,
        dt: f64,
        model: &Model,
        node_x: Vec<Vec2>,
        elements: Elements,
        rows: Vec<(Weights, Vec2, usize)>,
    ) -> Self {
        let attractor = model.attractor.map(|(position, strength)| AttractorTerm {
            position,
            strength,
            x: node_x,
        });
        let vstar = vec![Vec2::zeros(); nodes.len()];
        let Elements {
            quads,
            quad_terms,
            bends,
            bend_terms,
        } = elements;
        let mut prob = Problem {
            nodes,
            mass,
            vstar,
            dt,
            energy: model.energy,
            bending: model.bending,
            quads,
            quad_terms,
            bends,
            bend_terms,
            attractor,
            contacts: Vec::new(),
            rows,
            chol: Default::default(),
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

    /// `|F|`: each quadrature particle's force at unit strain of every
    /// mode (`vol / l0 (k + gamma + normal)`), each bending vertex's at a
    /// unit curvature change (`B inv_len^2`), each node's attractor force
    /// (`m s`), in quadrature.
    pub fn force_scale(&self) -> f64 {
        let e = &self.energy;
        let stiff = e.k + e.gamma + e.normal;
        let q: f64 = self
            .quads
            .iter()
            .map(|q| (q.vol / q.l0 * stiff).powi(2))
            .sum();
        let b: f64 = self
            .bends
            .iter()
            .map(|b| (self.bending * b.inv_len * b.inv_len).powi(2))
            .sum();
        let a: f64 = self.attractor.as_ref().map_or(0.0, |a| {
            self.mass.iter().map(|m| (m * a.strength).powi(2)).sum()
        });
        (q + b + a).sqrt()
    }

    /// Number of unknown nodes.
    #[cfg(test)]
    pub fn len(&self) -> usize {
        self.nodes.len()
    }
    /// Whether an external potential (the attractor, an obstacle's
    /// contact) acts: the elastic energy alone keeps the momentum.
    pub fn has_external(&self) -> bool {
        self.attractor.is_some() || !self.contacts.is_empty()
    }

    /// Sets the obstacles' contact terms (unknown indices).
    pub fn set_contacts(&mut self, contacts: Vec<ContactTerm>) {
        self.contacts = contacts;
    }

    /// The contact terms.
    pub fn contacts(&self) -> &[ContactTerm] {
        &self.contacts
    }
}
