//! Two velocity fields for yarn-on-yarn contact: the yarns held by a pin
//! (the *held* field) and the others (the *free* field) scatter into grids
//! of their own, each gets the grid update, the pin constraint acts on the
//! held field only, and where both fields have mass a Coulomb contact lets
//! them slide past each other (multi-velocity-field MPM contact:
//! Bardenhagen, Brackbill, Sulsky 2000, "The material-point method for
//! granular materials", CMAME 187; Bardenhagen et al. 2001, "An improved
//! contact algorithm for the material point method"; Nairn 2013).
//!
//! Why the partition is by pins: the pin constraint
//! ([`crate::mpm::laws::pins::constrain_grid`]) sets grid node velocities, so in a
//! field shared with other yarns it holds them too, wherever they share the
//! pinned vertices' stencils. What it does not cover: free yarns among
//! themselves (and held yarns among themselves) still share one field and
//! interact through it and the return mapping, as before.
//!
//! The contact at a node with masses `m_f`, `m_h` and velocities `v_f`,
//! `v_h` after the grid update and the pin constraint: the normal `n` from
//! the held to the free field is along the held field's mass gradient,
//! oriented by the difference of the two fields' gradients
//! ([`contact_normal`]; central differences of the node masses); if the
//! fields approach, `u = v_f - v_h` with `u . n < 0`, the
//! relative velocity becomes `u' = coulomb(u, n, mu)`
//! ([`crate::mpm::laws::contact::coulomb`]: no approach, tangential part reduced by
//! `mu` times the normal change, or stopped), shared about the centre of
//! mass: `v_f' = v_cm + m_h / (m_f + m_h) u'`, `v_h' = v_cm - m_f / (m_f +
//! m_h) u'` (momentum conserved, the same Coulomb form in impulse terms as
//! the obstacle law). At nodes of a pinned vertex's stencil the held field
//! is kinematic (`v_h' = v_h`, as for infinite mass), so the contact leaves
//! the pin constraint satisfied; the impulse it delivers there is added to
//! that pin's reaction. `mu` is `material.friction` (the derivation in
//! `docs/obstacle-contact.md`). Nodes are visited in the order of the
//! sorted active blocks, one at a time: the same bits for any thread count.

use crate::math::Vec2;
use crate::mpm::laws::contact::coulomb;
use crate::mpm::laws::pins::{self, PinEntry};
use crate::mpm::machinery::grid::{Grid, DVX, DVY, M, VX, VY};

/// The held field of a scene that has both held and free yarns, and the
/// scratch of its contact.
#[derive(Clone, Debug)]
pub struct Fields {
    /// The held field's grid (the free field is the simulation's own grid).
    pub grid: Grid,
    /// Whether each vertex is in the held field.
    pub vert_held: Vec<bool>,
    /// Whether each quadrature particle is in the held field.
    pub quad_held: Vec<bool>,
    /// Node masses of the free and held fields this substep (window storage).
    mass_free: Vec<f64>,
    mass_held: Vec<f64>,
    /// Per node, 1 + the pin whose vertex's stencil holds it, or 0.
    pinned_node: Vec<u32>,
}

impl Fields {
    /// Two fields when some yarns are held (`held_yarn[y]`: yarn `y` has a
    /// pinned vertex) and some are not; `None` otherwise (one field, the
    /// single-grid code path). `yarn_vertices` and `quad_left` are the
    /// particles' yarn ranges and quadrature particles' left vertices.
    pub fn of_yarns(
        held_yarn: &[bool],
        yarn_vertices: &[usize],
        quad_left: &[u32],
        grid: &Grid,
    ) -> Option<Self> {
        if held_yarn.iter().all(|&h| h) || !held_yarn.iter().any(|&h| h) {
            return None;
        }
        let mut vert_held = vec![false; *yarn_vertices.last().unwrap_or(&0)];
        for (y, &h) in held_yarn.iter().enumerate() {
            vert_held[yarn_vertices[y]..yarn_vertices[y + 1]].fill(h);
        }
        let quad_held = quad_left.iter().map(|&l| vert_held[l as usize]).collect();
        Some(Fields {
            grid: grid.clone(),
            vert_held,
            quad_held,
            mass_free: Vec::new(),
            mass_held: Vec::new(),
            pinned_node: Vec::new(),
        })
    }

    /// Keeps the node masses of both fields (call after the scatter, before
    /// the grid update consumes the scatter buffers).
    pub fn record_masses(&mut self, free: &Grid) {
        node_masses(free, &mut self.mass_free);
        node_masses(&self.grid, &mut self.mass_held);
    }

    /// The contact of the two fields (see the module documentation), after
    /// the grid update of both and the pin constraint on the held field
    /// (`entries`, [`pins::stencil_masses`]). Adds to `reactions[k]` the
    /// force pin `k` exerts through its kinematic nodes over `dt`.
    pub fn contact(
        &mut self,
        free: &mut Grid,
        entries: &[PinEntry],
        mu: f64,
        dt: f64,
        reactions: &mut [Vec2],
    ) {
        let geom = free.geom;
        debug_assert_eq!(geom, self.grid.geom, "both fields share one window");
        self.pinned_node.clear();
        self.pinned_node.resize(geom.storage(), 0);
        pins::mark_stencil_nodes(entries, &mut self.pinned_node);
        let (mf, mh) = (&self.mass_free, &self.mass_held);
        let rows = geom.nbi * crate::mpm::machinery::grid::BLOCK;
        let s = geom.stride;
        let grad = |m: &[f64], idx: usize| {
            let (i, j) = (idx / s, idx % s);
            let at = |ok: bool, k: usize| if ok { m[k] } else { 0.0 };
            Vec2::new(
                at(i + 1 < rows, idx + s) - at(i > 0, idx.wrapping_sub(s)),
                at(j + 1 < s, idx + 1) - at(j > 0, idx.wrapping_sub(1)),
            )
        };
        for &b in &free.active {
            if !self.grid.is_active[b as usize] {
                continue;
            }
            for idx in geom.block_nodes(b as usize) {
                let (m_f, m_h) = (mf[idx], mh[idx]);
                if m_f <= 0.0 || m_h <= 0.0 {
                    continue;
                }
                let Some(n) = contact_normal(grad(mf, idx), grad(mh, idx)) else {
                    continue;
                };
                let (nf, nh) = (&free.node[idx], &self.grid.node[idx]);
                let (vf, vh) = (Vec2::new(nf[VX], nf[VY]), Vec2::new(nh[VX], nh[VY]));
                let u = vf - vh;
                if u.dot(&n) >= 0.0 {
                    continue;
                }
                let u2 = coulomb(u, n, mu);
                let pin = self.pinned_node[idx];
                let (dvf, dvh) = if pin > 0 {
                    (vh + u2 - vf, Vec2::zeros())
                } else {
                    let inv = 1.0 / (m_f + m_h);
                    let vcm = (vf * m_f + vh * m_h) * inv;
                    (vcm + u2 * (m_h * inv) - vf, vcm - u2 * (m_f * inv) - vh)
                };
                add_velocity(&mut free.node[idx], dvf);
                add_velocity(&mut self.grid.node[idx], dvh);
                if pin > 0 {
                    reactions[pin as usize - 1] += dvf * (m_f / dt);
                }
            }
        }
    }
}

/// The contact normal from the held to the free field at a node, from the
/// two fields' mass gradients `gf`, `gh`: along the held field's gradient
/// (perpendicular to the held yarn's surface, so that the free yarn's own
/// ends do not plough into it), oriented toward the free field by the
/// difference `gf - gh`; the difference itself where the held gradient is
/// perpendicular to it (a node on the held yarn's centre line). `None`
/// where both vanish.
#[inline]
pub fn contact_normal(gf: Vec2, gh: Vec2) -> Option<Vec2> {
    let d = gf - gh;
    let s = gh.dot(&d);
    let n = if s != 0.0 { gh * s.signum() } else { d };
    let norm = n.norm();
    (norm > 0.0).then(|| n / norm)
}

/// Adds `dv` to a node's velocity and to its change over the substep (read
/// by the FLIP transfer only).
#[inline]
fn add_velocity(node: &mut [f64; 4], dv: Vec2) {
    node[VX] += dv.x;
    node[VY] += dv.y;
    node[DVX] += dv.x;
    node[DVY] += dv.y;
}

/// Node masses of `grid`'s scatter buffers, summed in chunk order (the
/// grid update's order) on its active blocks, zero elsewhere.
fn node_masses(grid: &Grid, out: &mut Vec<f64>) {
    let geom = grid.geom;
    out.clear();
    out.resize(geom.storage(), 0.0);
    for &b in &grid.active {
        let srcs: Vec<_> = grid
            .buffers
            .iter()
            .filter(|s| s.touched[b as usize])
            .collect();
        for idx in geom.block_nodes(b as usize) {
            let mut m = 0.0;
            for s in &srcs {
                m += s.node[idx][M];
            }
            out[idx] = m;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A free yarn one cell above a held one (centres at 1.2 and 2.2 cells,
    /// quadratic B-spline masses): at both shared nodes, and at the free
    /// yarn's end (its gradient along the yarn), the normal points up, from
    /// the held yarn to the free one.
    #[test]
    fn the_normal_points_from_the_held_yarn_to_the_free_one() {
        let w = |d: f64| {
            let d = d.abs();
            if d < 0.5 {
                0.75 - d * d
            } else if d < 1.5 {
                0.5 * (1.5 - d) * (1.5 - d)
            } else {
                0.0
            }
        };
        let grad_y = |centre: f64, j: f64| w(j + 1.0 - centre) - w(j - 1.0 - centre);
        for j in [1.0, 2.0] {
            let gh = Vec2::new(0.0, grad_y(1.2, j));
            let gf = Vec2::new(0.0, grad_y(2.2, j));
            assert_eq!(
                contact_normal(gf, gh),
                Some(Vec2::new(0.0, 1.0)),
                "node {j}"
            );
            let end = Vec2::new(-0.5, gf.y);
            assert_eq!(
                contact_normal(end, gh),
                Some(Vec2::new(0.0, 1.0)),
                "end, node {j}"
            );
        }
        // a held yarn without gradient there: the difference
        let n = contact_normal(Vec2::new(0.0, 2.0), Vec2::zeros()).unwrap();
        assert_eq!(n, Vec2::new(0.0, 1.0));
        assert_eq!(contact_normal(Vec2::zeros(), Vec2::zeros()), None);
    }
}
