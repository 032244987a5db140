//! Runs the evidence studies without the CLI:
//! `cargo run --release -p yarnsim-evidence --example evidence -- precision|stress|skip|roofline [--quick] [--out DIR]`
//! (precision also takes `--yarn-reference` and `--no-chain`).

use std::path::PathBuf;

use yarnsim_evidence::{precision, roofline, skip, stress, write_report};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let quick = args.iter().any(|a| a == "--quick");
    let out = args
        .iter()
        .position(|a| a == "--out")
        .and_then(|i| args.get(i + 1))
        .map_or(PathBuf::from("evidence-out"), PathBuf::from);
    let what = args.first().map(String::as_str).unwrap_or("precision");
    let t0 = std::time::Instant::now();
    let (text, files) = match what {
        "precision" => {
            let r = precision::run(&precision::PrecisionOptions {
                quick,
                yarn_reference: args.iter().any(|a| a == "--yarn-reference"),
                no_chain: args.iter().any(|a| a == "--no-chain"),
            })
            .unwrap_or_else(|e| panic!("{e}"));
            (r.to_text(), r.files())
        }
        "stress" => {
            let r = stress::run(&stress::StressOptions { quick });
            (r.to_text(), r.files())
        }
        "skip" => {
            let r = skip::run(&skip::SkipOptions::default()).unwrap_or_else(|e| panic!("{e}"));
            (r.to_text(), r.files())
        }
        "roofline" => {
            let r = roofline::run(&roofline::RooflineOptions::default())
                .unwrap_or_else(|e| panic!("{e}"));
            (r.to_text(), r.files())
        }
        other => panic!("unknown study {other:?}: precision, stress, skip or roofline"),
    };
    println!("{text}");
    for f in write_report(&out, &files).expect("output directory writable") {
        println!("wrote {f}");
    }
    println!("elapsed {:.1} s", t0.elapsed().as_secs_f64());
}
