//! Every floating-point flag of every subcommand rejects `nan`, `inf` and `-inf` at parse time,
//! naming the flag, with a nonzero exit code (a regression: `ballbot brake --heading-deg nan` used
//! to exit 0 because the flag was only read with actuator limits on). The flags are found by
//! clap's introspection of the command, so a new flag is covered without editing this test.

use ballbot_cli::Cli;
use clap::CommandFactory;
use std::any::TypeId;

/// `(subcommand path, flag)` of every argument whose value parser yields an `f32` or `f64`.
fn float_flags(cmd: &clap::Command, path: &mut Vec<String>, out: &mut Vec<(Vec<String>, String)>) {
    for arg in cmd.get_arguments() {
        let ty = arg.get_value_parser().type_id();
        if ty == TypeId::of::<f64>() || ty == TypeId::of::<f32>() {
            let flag = match arg.get_long() {
                Some(long) => format!("--{long}"),
                None => panic!(
                    "a positional float argument {:?}: extend this test",
                    arg.get_id()
                ),
            };
            out.push((path.clone(), flag));
        }
    }
    for sub in cmd.get_subcommands() {
        path.push(sub.get_name().to_owned());
        float_flags(sub, path, out);
        path.pop();
    }
}

#[test]
fn every_float_flag_rejects_non_finite_values_and_names_the_flag() {
    let mut flags = Vec::new();
    float_flags(&Cli::command(), &mut Vec::new(), &mut flags);
    // `brake` and `world` have float flags today; the walk must have found them.
    for sub in ["brake", "world"] {
        assert!(flags.iter().any(|(p, _)| p == &[sub]), "{sub}: {flags:?}");
    }
    assert!(
        flags
            .iter()
            .any(|(p, f)| p == &["brake"] && f == "--heading-deg")
    );
    for (path, flag) in &flags {
        for bad in ["nan", "inf", "-inf", "NaN", "1e999"] {
            let out = std::process::Command::new(env!("CARGO_BIN_EXE_ballbot"))
                .args(path)
                .arg(format!("{flag}={bad}"))
                .output()
                .unwrap();
            let stderr = String::from_utf8_lossy(&out.stderr);
            assert!(
                !out.status.success() && out.status.code() == Some(2),
                "ballbot {} {flag}={bad} was accepted ({:?}): {stderr}",
                path.join(" "),
                out.status
            );
            assert!(
                stderr.contains(flag.as_str()) && stderr.contains("finite"),
                "ballbot {} {flag}={bad}: the error does not name the flag: {stderr}",
                path.join(" ")
            );
        }
    }
    println!("{} float flags checked: {flags:?}", flags.len());
}

#[test]
fn a_finite_value_still_parses() {
    use clap::Parser;
    let cli = Cli::try_parse_from(["ballbot", "brake", "--heading-deg=-90.5"]).unwrap();
    match cli.command {
        ballbot_cli::Command::Brake(args) => assert_eq!(args.heading_deg, -90.5),
        other => panic!("{other:?}"),
    }
}
