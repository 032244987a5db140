//! The FMI 3.0 Float64 array output of the mass-spring system: every
//! particle's position. Its size is the bundled layout's particle count,
//! fixed when the FMU is generated.

/// `positions`, the FMI 3.0 array of all particle positions.
pub const VR_POSITIONS: u32 = crate::model_description::VR_ARRAY_BASE;

/// The FMI 3.0 array output `positions` (`[n, 3]`, row-major: x, y, z of
/// particle 0, then of particle 1, ...) of `n` particles.
pub fn positions_array(n: usize) -> crate::model_description::ArrayVariable {
    crate::model_description::ArrayVariable {
        name: "positions".into(),
        vr: VR_POSITIONS,
        dims: vec![n, 3],
        unit: Some("m"),
        description: format!(
            "The positions of the {n} particles, x, y and z of each (row-major {n} x 3)"
        ),
        initial: Vec::new(),
    }
}
