//! The angular momentum balance of the FLIP transfer.
//!
//! FLIP particles keep their own velocity but move with the grid's
//! (`x += dt v_grid`), so each substep a particle's moment changes by
//! `m (x_new - x_old) x v`, which is not zero when the two velocities
//! differ: the rotation the grid cannot resolve. At a fixed grid this drift
//! does not shrink with `dt` (it is a spatial error, ~dx^2). The transfers
//! themselves conserve angular momentum exactly (APIC's affine term), so
//! this is the only leak. After the gathers, each yarn's leak `S` is
//! returned as a rigid rotation of its free particles about the yarn's
//! centre of mass, `dv = -S / I perp(x - x_c)`, which changes neither the
//! linear momentum nor anything else to first order. APIC needs no such
//! step (its particles move with their own velocity).

use rayon::prelude::*;

use crate::math::{perp, Vec2};
use crate::mpm::machinery::particles::Particles;

/// Returns each yarn's moment leak of this substep to its free particles.
/// `pinned[i]`: vertex `i` is held by a pin (excluded: a pin's velocity is
/// prescribed).
pub fn balance(p: &mut Particles, pinned: &[bool]) {
    let yv = &p.yarn_vertices;
    let ny = yv.len() - 1;
    // split every per-particle array into per-yarn slices
    let mut vv: Vec<&mut [Vec2]> = Vec::with_capacity(ny);
    let mut qv: Vec<&mut [Vec2]> = Vec::with_capacity(ny);
    let (mut rv, mut rq) = (p.vert.v.as_mut_slice(), p.quad.v.as_mut_slice());
    let (vx, vm, vs) = (&p.vert.x, &p.vert.m, &p.vert.spin);
    let (qx, qm, qs) = (&p.quad.x, &p.quad.m, &p.quad.spin);
    for y in 0..ny {
        let n = yv[y + 1] - yv[y];
        let (a, b) = rv.split_at_mut(n);
        vv.push(a);
        rv = b;
        let (a, b) = rq.split_at_mut(n - 1);
        qv.push(a);
        rq = b;
    }
    vv.into_par_iter()
        .zip(qv)
        .enumerate()
        .for_each(|(y, (v, qvel))| {
            let (v0, q0) = (yv[y], yv[y] - y);
            let (nv, nq) = (v.len(), qvel.len());
            let pin = &pinned[v0..v0 + nv];
            let (vm, vs, vx) = (&vm[v0..v0 + nv], &vs[v0..v0 + nv], &vx[v0..v0 + nv]);
            let (qm, qs, qx) = (&qm[q0..q0 + nq], &qs[q0..q0 + nq], &qx[q0..q0 + nq]);
            // leak, mass and centre of the free particles
            let (mut s, mut m, mut c) = (0.0, 0.0, Vec2::zeros());
            for (((&mi, &si), xi), &p) in vm.iter().zip(vs).zip(vx).zip(pin) {
                if !p {
                    s += mi * si;
                    m += mi;
                    c += xi * mi;
                }
            }
            for ((&mk, &sk), xk) in qm.iter().zip(qs).zip(qx) {
                s += mk * sk;
                m += mk;
                c += xk * mk;
            }
            if s == 0.0 || m <= 0.0 {
                return;
            }
            c /= m;
            let mut inertia = 0.0;
            for ((&mi, xi), &p) in vm.iter().zip(vx).zip(pin) {
                if !p {
                    inertia += mi * (xi - c).norm_squared();
                }
            }
            for (&mk, xk) in qm.iter().zip(qx) {
                inertia += mk * (xk - c).norm_squared();
            }
            if inertia <= 0.0 {
                return;
            }
            let omega = -s / inertia;
            for ((vi, xi), &p) in v.iter_mut().zip(vx).zip(pin) {
                if !p {
                    *vi += perp(xi - c) * omega;
                }
            }
            for (vk, xk) in qvel.iter_mut().zip(qx) {
                *vk += perp(xk - c) * omega;
            }
        });
}
