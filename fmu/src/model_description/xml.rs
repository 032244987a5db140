//! `modelDescription.xml`: what it is written from ([`Description`]), the
//! writer, the GUID hash and the generation date; model-neutral.

use std::fmt::Write as _;

use yarnsim::mpm::driver::state::fnv1a;

use super::{real, ArrayVariable, VarType, Variable, LOG_CATEGORIES};

/// A GUID-formatted 128-bit hash of `text`.
pub fn guid_of(text: &str) -> String {
    let a = fnv1a(text.as_bytes());
    let b = fnv1a(format!("{text}\u{1}").as_bytes());
    format!(
        "{{{:08x}-{:04x}-{:04x}-{:04x}-{:012x}}}",
        a >> 32,
        (a >> 16) & 0xffff,
        a & 0xffff,
        b >> 48,
        b & 0xffff_ffff_ffff
    )
}

/// Escapes text for an XML attribute.
pub fn xml_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c if (c as u32) < 0x20 => out.push(' '),
            c => out.push(c),
        }
    }
    out
}

/// Units used by the variables with their SI base-unit exponents. The yarn
/// bundle is a 2D model per metre of depth: its energies are in J/m, its
/// stiffnesses and forces in N/m, its bending stiffness in N.m (N m^2 per
/// m of depth) and its line density in kg/m2 (kg per m of yarn per m of
/// depth); the mass-spring model is 3D (J).
pub const UNITS: [(&str, &str); 9] = [
    ("J", r#"kg="1" m="2" s="-2""#),
    ("J/m", r#"kg="1" m="1" s="-2""#),
    ("N.m", r#"kg="1" m="2" s="-2""#),
    ("N/m", r#"kg="1" s="-2""#),
    ("m/s", r#"m="1" s="-1""#),
    ("kg/m2", r#"kg="1" m="-2""#),
    ("m", r#"m="1""#),
    ("m/s2", r#"m="1" s="-2""#),
    ("s", r#"s="1""#),
];

/// What `modelDescription.xml` is written from.
#[derive(Clone, Debug, PartialEq)]
pub struct Description {
    pub identifier: &'static str,
    pub guid: String,
    pub description: String,
    pub variables: Vec<Variable>,
    /// `DefaultExperiment` stop time and step size in s.
    pub stop_time: f64,
    pub step_size: f64,
    /// What each output depends on ([`Dependency`]); an output without an
    /// entry depends on nothing (`dependencies=""`).
    pub dependencies: Vec<Dependency>,
    /// The Float64 array outputs of the FMI 3.0 FMU (not written by the
    /// FMI 2.0 writer).
    pub arrays: Vec<ArrayVariable>,
}

/// The `ModelStructure` dependencies of one output, by value reference.
#[derive(Clone, Debug, PartialEq)]
pub struct Dependency {
    pub output: u32,
    /// Inputs that change the output at the same instant, without a step
    /// (`<Outputs>`).
    pub step: Vec<u32>,
    /// Inputs and parameters its value after initialization depends on
    /// (`<InitialUnknowns>`).
    pub initial: Vec<u32>,
}

/// `generationDateAndTime` when `SOURCE_DATE_EPOCH` is not set: the date of
/// the interface version (fixed, so the same sources give the same XML).
pub const GENERATION_DATE_AND_TIME: &str = "2026-12-01T00:00:00Z";

/// `generationDateAndTime`: `SOURCE_DATE_EPOCH` (seconds since 1970, the
/// reproducible-builds convention) when set to an integer, else
/// [`GENERATION_DATE_AND_TIME`].
pub fn generation_date_and_time() -> String {
    std::env::var("SOURCE_DATE_EPOCH")
        .ok()
        .and_then(|v| v.trim().parse::<i64>().ok())
        .map(utc_date_time)
        .unwrap_or_else(|| GENERATION_DATE_AND_TIME.to_string())
}

/// ISO 8601 UTC of a Unix time (proleptic Gregorian calendar).
pub fn utc_date_time(secs: i64) -> String {
    let days = secs.div_euclid(86_400);
    let sod = secs.rem_euclid(86_400);
    // Days to civil date (H. Hinnant's algorithm).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}Z",
        sod / 3600,
        sod / 60 % 60,
        sod % 60
    )
}

/// The 1-based indices (positions in `<ModelVariables>`) of the outputs, in
/// order: how `<ModelStructure>` names them.
pub fn output_indices(vars: &[Variable]) -> Vec<usize> {
    vars.iter()
        .enumerate()
        .filter(|(_, v)| v.causality == "output")
        .map(|(i, _)| i + 1)
        .collect()
}

/// Writes the elements between `<CoSimulation>` and `<ModelVariables>` of
/// either FMI version: `UnitDefinitions` (the units for which `used` is
/// true), `LogCategories` (descriptions passed through `words`) and
/// `DefaultExperiment`.
pub fn write_units_to_experiment(
    x: &mut String,
    d: &Description,
    used: impl Fn(&str) -> bool,
    words: impl Fn(&str) -> String,
) {
    x.push_str("  <UnitDefinitions>\n");
    for (name, base) in UNITS.iter().filter(|(u, _)| used(u)) {
        let _ = writeln!(
            x,
            "    <Unit name=\"{}\"><BaseUnit {base}/></Unit>",
            xml_escape(name)
        );
    }
    x.push_str("  </UnitDefinitions>\n  <LogCategories>\n");
    for (name, what) in LOG_CATEGORIES {
        let _ = writeln!(
            x,
            "    <Category name=\"{name}\" description=\"{}\"/>",
            xml_escape(&words(what))
        );
    }
    x.push_str("  </LogCategories>\n");
    let _ = writeln!(
        x,
        "  <DefaultExperiment startTime=\"0.0\" stopTime=\"{}\" stepSize=\"{}\"/>",
        real(d.stop_time),
        real(d.step_size)
    );
}

/// What the two FMI versions write differently before `<ModelVariables>`.
pub struct Header<'a> {
    /// `fmiVersion`.
    pub version: &'a str,
    /// The name of the GUID (FMI 2.0) or token (FMI 3.0) attribute.
    pub id_attr: &'a str,
    /// The attributes of `<fmiModelDescription>` after
    /// `variableNamingConvention`.
    pub extra: &'a str,
    /// The attributes of `<CoSimulation>` after `modelIdentifier`.
    pub cosim: &'a str,
}

/// Writes the start of `modelDescription.xml` of either FMI version, up to
/// `<ModelVariables>`: the XML declaration, `<fmiModelDescription>`,
/// `<CoSimulation>` and [`write_units_to_experiment`].
pub fn write_header(
    d: &Description,
    h: Header<'_>,
    used: impl Fn(&str) -> bool,
    words: impl Fn(&str) -> String,
) -> String {
    let ident = d.identifier;
    let mut x = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = writeln!(
        x,
        "<fmiModelDescription fmiVersion=\"{}\" modelName=\"{ident}\" {}=\"{}\" description=\"{}\" generationTool=\"yarnsim-fmu {}\" generationDateAndTime=\"{}\" variableNamingConvention=\"structured\"{}>",
        h.version,
        h.id_attr,
        d.guid,
        xml_escape(&d.description),
        env!("CARGO_PKG_VERSION"),
        generation_date_and_time(),
        h.extra,
    );
    let _ = writeln!(
        x,
        "  <CoSimulation modelIdentifier=\"{ident}\" {}/>",
        h.cosim
    );
    write_units_to_experiment(&mut x, d, used, words);
    x.push_str("  <ModelVariables>\n");
    x
}

/// Writes the start of a variable element of either FMI version, up to its
/// `variability` attribute (`attrs`: causality and variability).
pub fn write_variable(
    x: &mut String,
    tag: &str,
    name: &str,
    vr: u32,
    description: &str,
    (causality, variability): (&str, &str),
) {
    let _ = write!(
        x,
        "    <{tag} name=\"{}\" valueReference=\"{vr}\" description=\"{}\" causality=\"{causality}\" variability=\"{variability}\"",
        xml_escape(name),
        xml_escape(description),
    );
}

/// Writes a ` unit` attribute where there is a unit.
pub fn write_unit(x: &mut String, unit: Option<&str>) {
    if let Some(u) = unit {
        let _ = write!(x, " unit=\"{}\"", xml_escape(u));
    }
}

/// Writes `modelDescription.xml`; only the units the variables use are defined.
pub fn write_model_description(d: &Description) -> String {
    let vars = &d.variables;
    let used = |u: &str| vars.iter().any(|v| v.unit == Some(u));
    let mut x = write_header(d, HEADER, used, |w| w.to_string());
    for (i, v) in vars.iter().enumerate() {
        let _ = writeln!(x, "    <!-- index {} -->", i + 1);
        let attrs = (v.causality, v.variability);
        write_variable(
            &mut x,
            "ScalarVariable",
            &v.name,
            v.vr,
            &v.description,
            attrs,
        );
        // Parameters are initial="exact" by default, inputs take no initial,
        // outputs default to initial="calculated".
        x.push_str(">\n      <");
        x.push_str(match v.ty {
            VarType::Real => "Real",
            VarType::Integer => "Integer",
            VarType::Boolean => "Boolean",
            VarType::String => "String",
        });
        write_unit(&mut x, v.unit);
        if let Some(s) = &v.start {
            let _ = write!(x, " start=\"{}\"", xml_escape(s));
        }
        x.push_str("/>\n    </ScalarVariable>\n");
    }
    x.push_str("  </ModelVariables>\n  <ModelStructure>\n    <Outputs>\n");
    let outputs = output_indices(vars);
    // 1-based indices of value references, ascending.
    let indices = |vrs: &[u32]| -> String {
        let mut ix: Vec<usize> = vrs
            .iter()
            .map(|vr| {
                1 + vars
                    .iter()
                    .position(|v| v.vr == *vr)
                    .unwrap_or_else(|| panic!("dependency on unknown value reference {vr}"))
            })
            .collect();
        ix.sort_unstable();
        ix.iter()
            .map(|i| i.to_string())
            .collect::<Vec<_>>()
            .join(" ")
    };
    let deps_of = |i: usize, initial: bool| -> String {
        d.dependencies
            .iter()
            .find(|dep| dep.output == vars[i - 1].vr)
            .map(|dep| indices(if initial { &dep.initial } else { &dep.step }))
            .unwrap_or_default()
    };
    for &i in &outputs {
        let _ = writeln!(
            x,
            "      <Unknown index=\"{i}\" dependencies=\"{}\"/>",
            deps_of(i, false)
        );
    }
    x.push_str("    </Outputs>\n    <InitialUnknowns>\n");
    for &i in &outputs {
        let _ = writeln!(
            x,
            "      <Unknown index=\"{i}\" dependencies=\"{}\"/>",
            deps_of(i, true)
        );
    }
    x.push_str("    </InitialUnknowns>\n  </ModelStructure>\n</fmiModelDescription>\n");
    x
}

/// The FMI 2.0 `<fmiModelDescription>` and `<CoSimulation>` attributes.
const HEADER: Header = Header {
    version: "2.0",
    id_attr: "guid",
    extra: " numberOfEventIndicators=\"0\"",
    cosim: "canHandleVariableCommunicationStepSize=\"true\" canInterpolateInputs=\"false\" maxOutputDerivativeOrder=\"0\" canRunAsynchronuously=\"false\" canBeInstantiatedOnlyOncePerProcess=\"false\" canNotUseMemoryManagementFunctions=\"true\" canGetAndSetFMUstate=\"true\" canSerializeFMUstate=\"true\" providesDirectionalDerivative=\"false\"",
};
