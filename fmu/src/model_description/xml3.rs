//! `modelDescription.xml` of the FMI 3.0 Co-Simulation FMU (FMI 3.0,
//! chapter 2.4 and section 4.3), written from the same [`Description`] as
//! the FMI 2.0 one plus its Float64 arrays; model-neutral.
//!
//! What differs from the FMI 2.0 file: `fmiVersion="3.0"` and an
//! `instantiationToken` (the FMI 2.0 GUID of the same scene), the
//! independent variable `time` (value reference [`VR_TIME`]), typed variable
//! elements (`Float64`, `Int32`, `Boolean`, `String` with a `<Start>`
//! child), the arrays with their `<Dimension>`s, and a `ModelStructure` of
//! `<Output>` and `<InitialUnknown>` elements that name value references,
//! not indices.

use std::fmt::Write as _;

use super::{
    write_header, write_unit, write_variable, xml_escape, ArrayVariable, Description, Header,
    VarType, Variable, VR_TIME,
};

/// The FMI 3.0 type element of a variable type.
pub fn fmi3_type(t: VarType) -> &'static str {
    match t {
        VarType::Real => "Float64",
        VarType::Integer => "Int32",
        VarType::Boolean => "Boolean",
        VarType::String => "String",
    }
}

/// A description in FMI 3.0 words (the FMI 2.0 function and status names
/// the shared variable tables use, such as `fmi2DoStep`, `fmi2Error`).
pub fn fmi3_words(text: &str) -> String {
    text.replace("fmi2", "fmi3")
}

/// Value references as a `dependencies` list: ascending, space-separated.
fn vr_list(vrs: &[u32]) -> String {
    let mut v = vrs.to_vec();
    v.sort_unstable();
    v.iter().map(u32::to_string).collect::<Vec<_>>().join(" ")
}

/// One scalar variable element.
fn scalar(x: &mut String, v: &Variable) {
    let ty = fmi3_type(v.ty);
    let description = fmi3_words(&v.description);
    write_variable(
        x,
        ty,
        &v.name,
        v.vr,
        &description,
        (v.causality, v.variability),
    );
    write_unit(x, v.unit);
    match (&v.start, v.ty) {
        (Some(s), VarType::String) => {
            let _ = writeln!(
                x,
                ">\n      <Start value=\"{}\"/>\n    </{ty}>",
                xml_escape(s)
            );
        }
        (Some(s), _) => {
            let _ = writeln!(x, " start=\"{}\"/>", xml_escape(s));
        }
        (None, _) => x.push_str("/>\n"),
    }
}

/// One Float64 array output element.
fn array(x: &mut String, a: &ArrayVariable) {
    let attrs = ("output", "continuous");
    write_variable(x, "Float64", &a.name, a.vr, &a.description, attrs);
    write_unit(x, a.unit);
    x.push_str(">\n");
    for n in &a.dims {
        let _ = writeln!(x, "      <Dimension start=\"{n}\"/>");
    }
    x.push_str("    </Float64>\n");
}

/// Every output of the FMI 3.0 FMU with its `<Output>` dependencies (inputs
/// that change it at the same instant) and its `<InitialUnknown>` ones, in
/// `ModelVariables` order: what the modelDescription says and what
/// `fmi3GetVariableDependencies` answers.
pub fn fmi3_outputs(d: &Description) -> Vec<(u32, Vec<u32>, Vec<u32>)> {
    let dep = |vr: u32| d.dependencies.iter().find(|dep| dep.output == vr);
    d.variables
        .iter()
        .filter(|v| v.causality == "output")
        .map(|v| {
            let (step, initial) = dep(v.vr)
                .map(|dep| (dep.step.clone(), dep.initial.clone()))
                .unwrap_or_default();
            (v.vr, step, initial)
        })
        .chain(
            d.arrays
                .iter()
                .map(|a| (a.vr, Vec::new(), a.initial.clone())),
        )
        .collect()
}

/// Writes the FMI 3.0 `modelDescription.xml`; only the units the variables
/// use are defined.
pub fn write_model_description_fmi3(d: &Description) -> String {
    let vars = &d.variables;
    let used = |u: &str| {
        u == "s"
            || vars.iter().any(|v| v.unit == Some(u))
            || d.arrays.iter().any(|a| a.unit == Some(u))
    };
    let mut x = write_header(d, HEADER, used, fmi3_words);
    let _ = writeln!(
        x,
        "    <Float64 name=\"time\" valueReference=\"{VR_TIME}\" description=\"Simulation time\" causality=\"independent\" variability=\"continuous\" unit=\"s\"/>"
    );
    for v in vars {
        scalar(&mut x, v);
    }
    for a in &d.arrays {
        array(&mut x, a);
    }
    x.push_str("  </ModelVariables>\n  <ModelStructure>\n");
    let outputs = fmi3_outputs(d);
    for (vr, step, _) in &outputs {
        let _ = writeln!(
            x,
            "    <Output valueReference=\"{vr}\" dependencies=\"{}\"/>",
            vr_list(step)
        );
    }
    for (vr, _, initial) in &outputs {
        let _ = writeln!(
            x,
            "    <InitialUnknown valueReference=\"{vr}\" dependencies=\"{}\"/>",
            vr_list(initial)
        );
    }
    x.push_str("  </ModelStructure>\n</fmiModelDescription>\n");
    x
}

/// The FMI 3.0 `<fmiModelDescription>` and `<CoSimulation>` attributes.
const HEADER: Header = Header {
    version: "3.0",
    id_attr: "instantiationToken",
    extra: "",
    cosim: "canHandleVariableCommunicationStepSize=\"true\" maxOutputDerivativeOrder=\"0\" canBeInstantiatedOnlyOncePerProcess=\"false\" canGetAndSetFMUState=\"true\" canSerializeFMUState=\"true\" providesDirectionalDerivatives=\"false\" providesAdjointDerivatives=\"false\" providesPerElementDependencies=\"false\" hasEventMode=\"false\" providesIntermediateUpdate=\"false\" mightReturnEarlyFromDoStep=\"false\" canReturnEarlyAfterIntermediateUpdate=\"false\" providesEvaluateDiscreteStates=\"false\"",
};
