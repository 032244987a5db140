//! The built-in scenes: each one a TOML file under `scenes/` in the
//! repository (`scenes/yarn/`, `scenes/massspring/`), embedded in the
//! library and parsed by the loader of users' files
//! ([`Scene::from_toml_str`]). One file per name; `reference` and `default`
//! are aliases of `yarn-reference`.

use super::{MassSpringScene, Scene, YarnScene};

/// The scene used when none is named.
pub const DEFAULT_SCENE: &str = "yarn-reference";

/// One built-in: its name, the one-line summary `yarnsim scenes` lists, and
/// the text of its file.
struct Builtin {
    name: &'static str,
    summary: &'static str,
    text: &'static str,
}

/// The table of built-ins from `dir / name: summary` rows, each row's
/// text the file `scenes/<dir>/<name>.toml` (a macro: `include_str!` takes
/// a literal path only).
macro_rules! builtins {
    ($($dir:literal / $name:literal: $summary:literal,)*) => {
        [$(Builtin {
            name: $name,
            summary: $summary,
            text: include_str!(concat!("../../scenes/", $dir, "/", $name, ".toml")),
        },)*]
    };
}

/// Every built-in scene, in the order `yarnsim scenes` lists them.
#[rustfmt::skip]
const BUILTINS: [Builtin; 6] = builtins! {
    "yarn" / "yarn-reference": "Jiang et al. 2017 reference: 12 yarns x 200 vertices fall onto three circles (256^2 grid, dt 4e-5)",
    "yarn" / "yarn-vertical": "the reference bundle turned upright: 12 vertical yarns drop onto the circles",
    "yarn" / "yarn-drape": "one diagonal yarn of 400 vertices drapes over a single circle",
    "massspring" / "wire": "course notes: 11-particle wire (mass 1, length 1), top end driven on a circle, 100 frames of 0.05 s",
    "massspring" / "three-particle": "Baraff-Witkin 1998: three particles joined by two springs, the 9x9 backward-Euler system",
    "massspring" / "cloth": "Wang 2015, Provot 1995: 21x21 sheet (10x10 m, k 8000) pinned at two corners falls onto a sphere",
};

/// Other names of built-ins: `(alias, name)`.
const ALIASES: [(&str, &str); 2] = [
    ("reference", "yarn-reference"),
    ("default", "yarn-reference"),
];

/// `(name, one-line description)` of every built-in scene.
pub fn builtin_names() -> Vec<(&'static str, &'static str)> {
    BUILTINS.iter().map(|b| (b.name, b.summary)).collect()
}

/// The text of a built-in scene's file, by name or alias.
pub fn builtin_toml(name: &str) -> Option<&'static str> {
    let name = ALIASES
        .iter()
        .find(|(alias, _)| *alias == name)
        .map_or(name, |(_, target)| *target);
    BUILTINS.iter().find(|b| b.name == name).map(|b| b.text)
}

/// A built-in scene by name or alias, parsed from its embedded file.
pub fn builtin(name: &str) -> Option<Scene> {
    builtin_toml(name).map(|text| {
        Scene::from_toml_str(text)
            .unwrap_or_else(|e| panic!("the built-in scene file of {name:?} does not load: {e}"))
    })
}

/// The built-in yarn scene `name` (a `yarn-*` name of [`builtin_names`]).
///
/// # Panics
/// If `name` is no built-in yarn scene.
fn builtin_yarn(name: &str) -> YarnScene {
    match builtin(name) {
        Some(Scene::Yarn(s)) => s,
        _ => panic!("{name:?} is no built-in yarn scene"),
    }
}

/// The built-in mass-spring scene `name` (`wire`, `three-particle` or
/// `cloth`).
///
/// # Panics
/// If `name` is no built-in mass-spring scene.
fn builtin_mass_spring(name: &str) -> MassSpringScene {
    match builtin(name) {
        Some(Scene::MassSpring(s)) => s,
        _ => panic!("{name:?} is no built-in mass-spring scene"),
    }
}

/// The reference scene (`scenes/yarn/yarn-reference.toml`, the reference
/// Taichi implementation of Jiang et al. 2017's yarn bundle): 12 horizontal
/// yarns of 200 vertices (4788 particles), 256^2 grid, dt 4e-5, three
/// circles of radius 0.08.
pub fn yarn_reference() -> YarnScene {
    builtin_yarn("yarn-reference")
}

/// The course lecture notes' wire (`scenes/massspring/wire.toml`): 11
/// particles from `(0, 0, 0.5)` to `(0, -1, 0.5)`, total mass 1,
/// `youngs_modulus` 100 (k = 1000 N/m per spring), damping 100 N s/m,
/// gravity 9.81, the top particle driven on the circle of radius 0.5 about
/// the origin in the x-z plane with period 5 s (= 100 frames of 0.05 s).
pub fn wire() -> MassSpringScene {
    builtin_mass_spring("wire")
}

/// Baraff and Witkin 1998's three-particle system
/// (`scenes/massspring/three-particle.toml`): masses 1, 2 and 1.5 kg,
/// springs 0-1 and 1-2 (stiffness 50 N/m, both stretched), no constraints,
/// so the whole 9x9 system `A = M - h^2 K` is solved.
pub fn three_particle() -> MassSpringScene {
    builtin_mass_spring("three-particle")
}

/// The cloth (Wang 2015; Müller et al. 2007; Provot 1995;
/// `scenes/massspring/cloth.toml`): 21 x 21 vertices spanning 10 x 10 m in
/// the plane y = 0, vertex `(i, j)` at `(5 - 10 i/20, 0, 5 - 10 j/20)`, mass
/// 1 each, springs of k = 8000 N/m on the triangle edges, vertices 0 and 20
/// pinned, h = 1/30 s, velocity damping 0.99 per step, gravity 9.8, and a
/// sphere of radius 2.7 centred at `(0, -3, 0)` (the Unity cloth scripts
/// move it with the mouse; this position puts it in the path of the
/// swinging sheet).
pub fn cloth() -> MassSpringScene {
    builtin_mass_spring("cloth")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_name_has_one_file_and_every_file_its_name() {
        for (i, b) in BUILTINS.iter().enumerate() {
            assert!(BUILTINS[..i]
                .iter()
                .all(|o| o.name != b.name && o.text != b.text));
            assert_eq!(builtin(b.name).unwrap().name(), b.name);
        }
        for (alias, target) in ALIASES {
            assert!(BUILTINS.iter().all(|b| b.name != alias));
            assert_eq!(builtin(alias), builtin(target));
        }
        assert!(builtin("no-such-scene").is_none());
    }
}
