//! The variable types of `modelDescription.xml` and the static-table
//! mechanics: a [`VarSpec`] row (name, value reference, type, causality,
//! variability, unit, start, description) over a model's scene type `S`,
//! and for the Real parameters the scene field ([`SceneField`]) that the
//! getter and setter use.

/// The FMI base type of a variable.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VarType {
    Real,
    Integer,
    Boolean,
    String,
}

/// A variable of the FMU as it appears in `modelDescription.xml`.
#[derive(Clone, Debug, PartialEq)]
pub struct Variable {
    pub name: String,
    pub vr: u32,
    pub ty: VarType,
    /// `"parameter"`, `"input"` or `"output"`.
    pub causality: &'static str,
    /// `"fixed"`, `"discrete"` or `"continuous"`.
    pub variability: &'static str,
    pub unit: Option<&'static str>,
    /// Start value as written in the XML (inputs and parameters only).
    pub start: Option<String>,
    pub description: String,
}

/// A Float64 array output of the FMI 3.0 FMU (FMI 2.0 has no arrays): its
/// dimensions are fixed by the bundled scene when the FMU is generated.
#[derive(Clone, Debug, PartialEq)]
pub struct ArrayVariable {
    pub name: String,
    pub vr: u32,
    /// The size of each dimension, row-major (`[n, 2]`: n points x, y).
    pub dims: Vec<usize>,
    pub unit: Option<&'static str>,
    pub description: String,
    /// Inputs and parameters its value after initialization depends on
    /// (`<InitialUnknown>`); it depends on no input at the same instant.
    pub initial: Vec<u32>,
}

impl ArrayVariable {
    /// The number of values (the product of the dimensions).
    pub fn len(&self) -> usize {
        self.dims.iter().product()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Formats an `f64` so that it reads back to the same bits (shortest round trip).
pub fn real(v: f64) -> String {
    format!("{v:?}")
}

fn boolean(b: bool) -> String {
    if b { "true" } else { "false" }.to_string()
}

/// A Real parameter that lives in the scene (of type `S`): how to read and
/// override it.
pub struct SceneField<S> {
    pub get: fn(&S) -> f64,
    pub set: fn(&mut S, f64),
    /// Must be > 0 (else >= 0).
    pub positive: bool,
    /// Largest accepted value.
    pub max: f64,
}

/// Where a variable's start value comes from (a scene of type `S`).
pub enum Start<S> {
    /// Outputs have none.
    None,
    /// A Real parameter in the scene (also its getter and setter).
    Scene(SceneField<S>),
    /// A Real read from the scene.
    Real(fn(&S) -> f64),
    /// A Boolean read from the scene.
    Bool(fn(&S) -> bool),
    /// A fixed text.
    Text(&'static str),
    /// A name read from the scene.
    Name(fn(&S) -> &'static str),
}

/// One row of a model's variable table; `S` is the scene type its start
/// values are read from (the yarn scene, or the mass-spring layout).
pub struct VarSpec<S> {
    pub name: &'static str,
    pub vr: u32,
    pub ty: VarType,
    pub causality: &'static str,
    pub variability: &'static str,
    pub unit: Option<&'static str>,
    pub start: Start<S>,
    pub description: &'static str,
}

/// `Clone` and `Copy` for a table type over any scene type `S` (the
/// derives would ask `S: Copy`; these types hold only function pointers and
/// static data).
macro_rules! copy_for_any_scene {
    ($($t:ident),*) => {$(
        impl<S> Clone for $t<S> {
            fn clone(&self) -> Self {
                *self
            }
        }
        impl<S> Copy for $t<S> {}
    )*};
}
copy_for_any_scene!(SceneField, Start, VarSpec);

impl<S> Start<S> {
    /// The base type of a variable with this start value (outputs, which
    /// have none, are Real).
    pub const fn var_type(&self) -> VarType {
        match self {
            Start::None | Start::Scene(_) | Start::Real(_) => VarType::Real,
            Start::Bool(_) => VarType::Boolean,
            Start::Text(_) | Start::Name(_) => VarType::String,
        }
    }
}

impl<S> VarSpec<S> {
    /// The variable as written in `modelDescription.xml`, for this scene.
    pub fn variable(&self, scene: &S) -> Variable {
        Variable {
            name: self.name.to_string(),
            vr: self.vr,
            ty: self.ty,
            causality: self.causality,
            variability: self.variability,
            unit: self.unit,
            start: match self.start {
                Start::None => None,
                Start::Scene(f) => Some(real((f.get)(scene))),
                Start::Real(f) => Some(real(f(scene))),
                Start::Bool(f) => Some(boolean(f(scene))),
                Start::Text(t) => Some(t.to_string()),
                Start::Name(f) => Some(f(scene).to_string()),
            },
            description: self.description.to_string(),
        }
    }
}

/// What an input or parameter row of a table is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Causality {
    /// An input: continuous if Real, else discrete.
    Input,
    /// A fixed parameter: set before the end of initialization only.
    Parameter,
}

/// An input or fixed-parameter row; its type follows from its start value.
pub const fn var<S>(
    causality: Causality,
    name: &'static str,
    vr: u32,
    unit: Option<&'static str>,
    start: Start<S>,
    description: &'static str,
) -> VarSpec<S> {
    let ty = start.var_type();
    VarSpec {
        name,
        vr,
        ty,
        causality: match causality {
            Causality::Input => "input",
            Causality::Parameter => "parameter",
        },
        variability: match (causality, ty) {
            (Causality::Parameter, _) => "fixed",
            (Causality::Input, VarType::Real) => "continuous",
            (Causality::Input, _) => "discrete",
        },
        unit,
        start,
        description,
    }
}

/// A continuous Real output row.
pub const fn output<S>(
    name: &'static str,
    vr: u32,
    unit: Option<&'static str>,
    description: &'static str,
) -> VarSpec<S> {
    VarSpec {
        name,
        vr,
        ty: VarType::Real,
        causality: "output",
        variability: "continuous",
        unit,
        start: Start::None,
        description,
    }
}

/// The name and causality of the row of `table` with value reference `vr`.
pub fn table_name<S>(table: &[VarSpec<S>], vr: u32) -> Option<(&'static str, &'static str)> {
    table
        .iter()
        .find(|v| v.vr == vr)
        .map(|v| (v.name, v.causality))
}

/// The name and causality of the common variable ([`super::COMMON_VARIABLES`])
/// with value reference `vr`.
pub fn common_name(vr: u32) -> Option<(&'static str, &'static str)> {
    super::COMMON_VARIABLES
        .iter()
        .find(|c| c.1 == vr)
        .map(|c| (c.0, c.2))
}
