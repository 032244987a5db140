//! `yarnsim materials`: the yarn presets of `[material] preset = "NAME"`.

use std::fmt::Write as _;

use yarnsim::scene::presets::PRESETS;

/// One row per preset (name, linear density, diameter, axial stiffness,
/// bending rigidity, friction on yarn and on solids, axial wave speed) and
/// its description under it, then how a scene uses them.
pub fn list_materials() -> String {
    let width = PRESETS.iter().map(|p| p.name.len()).max().unwrap_or(0);
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{:<width$}  {:>5}  {:>6}  {:>6}  {:>10}  {:>7}  {:>8}  {:>7}",
        "name", "tex", "d (mm)", "EA (N)", "EI (N m^2)", "mu yarn", "mu solid", "c (m/s)"
    );
    for p in PRESETS {
        let c = p.properties().wave_speed();
        let _ = writeln!(
            out,
            "{:<width$}  {:>5.1}  {:>6.3}  {:>6.0}  {:>10.2e}  {:>7.2}  {:>8.2}  {:>7.0}",
            p.name,
            p.tex,
            p.diameter * 1e3,
            p.ea,
            p.ei,
            p.friction,
            p.friction_solid,
            c,
        );
        let _ = writeln!(out, "  {}", p.description);
    }
    let _ = writeln!(
        out,
        "\ntex: g per km; mu: friction on yarn and on solids (obstacles); c = sqrt(EA / (tex 1e-6)):\n\
         the axial wave speed, which bounds the explicit substep (dt = \"auto\": about dx / c);\n\
         [time] axial = \"implicit\" (with transfer.scheme = \"apic\", or FLIP with a\n\
         transfer.flip_time) solves the fibre stretch by backward Euler and lifts that bound\n\
         (then the cross-section and shear waves set dt).\n\
         Use: [material] preset = \"NAME\"; any field overrides the preset's. Per metre of depth\n\
         at the sheet spacing s (default: the diameter): k = EA / s, density = tex 1e-6 / s,\n\
         bending = EI / s; a pin force per metre of depth times s is one yarn's. Sources, and\n\
         which values are derived or estimated: docs/yarn-materials.md, docs/references.md."
    );
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_preset_is_listed_within_the_width() {
        let text = list_materials();
        for p in PRESETS {
            assert!(text.contains(p.name), "{}", p.name);
        }
        for line in text.lines() {
            assert!(line.chars().count() <= crate::table::MAX_WIDTH, "{line}");
        }
    }
}
