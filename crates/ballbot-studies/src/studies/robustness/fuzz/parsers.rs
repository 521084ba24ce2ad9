//! Fuzzing the parsers of the TOML files the tools read: scenarios (`ballbot simulate`), robot
//! parameters (`examples/params`, the gains example), a plane's parameters (`ballbot brake
//! --params`) and world parameters. Each mutation of a valid file (a value replaced by a
//! hostile token, a line deleted, duplicated or renamed, the text truncated, garbage
//! inserted) must give a value or an error, never a panic; where the mutation put a wrong or
//! non-finite value under a key, the error must name the key.

use super::hostile::{chance, index};
use crate::studies::scenario::Scenario;
use ballbot_core::{BallbotParams, WipParams};
use ballbot_world::world::WorldParams;
use rand_chacha::ChaCha8Rng;
use rand_chacha::rand_core::SeedableRng;
use serde::Serialize;

/// The parsers' tally.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct ParserFuzz {
    /// Mutated files parsed.
    pub files: u64,
    /// Accepted (a valid file after all).
    pub accepted: u64,
    /// Rejected with an error.
    pub rejected: u64,
    /// Panics (must be 0).
    pub panics: u64,
    /// Mutations that put a wrong or non-finite value under a key.
    pub targeted: u64,
    /// ... of which the error named the key.
    pub named_the_key: u64,
    /// ... of which the file was accepted anyway (the token was a valid value).
    pub targeted_accepted: u64,
    /// Up to five errors that did not name the key they should have.
    pub unnamed: Vec<String>,
    /// Up to five wrong values that were accepted (`key = token`).
    pub accepted_wrong: Vec<String>,
}

/// The valid files mutated, with the parser of each.
type Parse = fn(&str) -> Result<(), String>;

fn bases() -> Vec<(&'static str, String, Parse)> {
    let toml_of = |v: Result<String, toml::ser::Error>| v.unwrap_or_default();
    // The files' first line, an editor's `#:schema` comment, is not part of what is mutated:
    // the seeded mutations, and so the published tallies, stay those of the files before it.
    let without_schema_line = |text: &str| {
        text.strip_prefix("#:schema")
            .and_then(|rest| rest.split_once('\n'))
            .map_or(text, |(_, body)| body)
            .to_owned()
    };
    vec![
        (
            "scenario",
            without_schema_line(include_str!(
                "../../../../../../scenarios/balance_stiction_lqr.toml"
            )),
            parse_scenario,
        ),
        (
            "scenario",
            without_schema_line(include_str!(
                "../../../../../../scenarios/piptb_lqr_pi.toml"
            )),
            parse_scenario,
        ),
        (
            "robot",
            without_schema_line(include_str!(
                "../../../../../../examples/params/miapure_60kg.toml"
            )),
            |t| {
                let p: BallbotParams<f64> = toml::from_str(t).map_err(|e| e.to_string())?;
                p.validate().map_err(|e| e.to_string())
            },
        ),
        (
            "plane",
            toml_of(toml::to_string(&WipParams::<f64>::miapure_60kg())),
            |t| {
                let p: WipParams<f64> = toml::from_str(t).map_err(|e| e.to_string())?;
                p.validate().map_err(|e| e.to_string())
            },
        ),
        (
            "world",
            toml_of(toml::to_string(&WorldParams::miapure_60kg())),
            |t| {
                let p: WorldParams = toml::from_str(t).map_err(|e| e.to_string())?;
                p.validate().map_err(|e| e.to_string())
            },
        ),
    ]
}

/// A scenario as `ballbot simulate` reads it: parsed, validated, its simulator built (which
/// checks the controller, sensor and friction sections).
fn parse_scenario(text: &str) -> Result<(), String> {
    let scenario = Scenario::from_toml_str(text).map_err(|e| e.to_string())?;
    scenario.simulator().map(|_| ()).map_err(|e| e.to_string())
}

/// Values no key of these files accepts as they are.
const WRONG: [&str; 10] = [
    "nan",
    "inf",
    "-inf",
    "1e309",
    "\"text\"",
    "[1, 2]",
    "{ a = 1 }",
    "true",
    "-1e300",
    "1979-05-27",
];

/// Parses `files` seeded mutations of the valid files.
pub fn fuzz_parsers(seed: u64, files: u64) -> ParserFuzz {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let bases = bases();
    let mut tally = ParserFuzz::default();
    for _ in 0..files {
        let (_, text, parse) = &bases[index(&mut rng, bases.len())];
        let lines: Vec<&str> = text.lines().collect();
        let (mutated, target) = mutate(&mut rng, &lines);
        let line = target.as_ref().and_then(|k| {
            mutated
                .lines()
                .find(|l| l.trim_start().starts_with(&format!("{k} = ")))
                .map(str::to_owned)
        });
        tally.files += 1;
        let outcome = std::panic::catch_unwind(|| parse(&mutated));
        match outcome {
            Err(_) => tally.panics += 1,
            Ok(Ok(())) => {
                tally.accepted += 1;
                if target.is_some() {
                    tally.targeted += 1;
                    tally.targeted_accepted += 1;
                    if tally.accepted_wrong.len() < 5 {
                        tally.accepted_wrong.push(line.unwrap_or_default());
                    }
                }
            }
            Ok(Err(message)) => {
                tally.rejected += 1;
                if let Some(key) = target {
                    tally.targeted += 1;
                    if message.contains(&key) {
                        tally.named_the_key += 1;
                    } else if tally.unnamed.len() < 5 {
                        tally.unnamed.push(format!("`{key}`: {message}"));
                    }
                }
            }
        }
    }
    tally
}

/// One mutation; the key whose value it replaced by a wrong one, if it did.
fn mutate(rng: &mut ChaCha8Rng, lines: &[&str]) -> (String, Option<String>) {
    let mut out: Vec<String> = lines.iter().map(|l| (*l).to_owned()).collect();
    let keyed: Vec<usize> = (0..out.len())
        .filter(|&i| {
            let l = out[i].trim_start();
            !l.starts_with('#') && !l.starts_with('[') && l.contains(" = ")
        })
        .collect();
    if keyed.is_empty() {
        return (out.join("\n"), None);
    }
    let line = keyed[index(rng, keyed.len())];
    let key = out[line]
        .split(" = ")
        .next()
        .unwrap_or_default()
        .trim()
        .to_owned();
    let mut target = None;
    match index(rng, 7) {
        0..=2 => {
            let token = WRONG[index(rng, WRONG.len())];
            let was_bool = out[line].ends_with("= true") || out[line].ends_with("= false");
            out[line] = format!("{key} = {token}");
            // `true` is a right value for a flag.
            if !(was_bool && token == "true") {
                target = Some(key);
            }
        }
        3 => {
            out.remove(line);
        }
        4 => {
            let copy = out[line].clone();
            out.insert(line, copy);
        }
        5 => out[line] = format!("{key}_renamed = 1.0"),
        _ => {
            let mut text = out.join("\n");
            let mut cut = index(rng, text.len().max(1)).min(text.len());
            while !text.is_char_boundary(cut) {
                cut -= 1;
            }
            if chance(rng, 0.5) {
                text.truncate(cut);
            } else {
                let at = cut;
                let garbage: String = (0..1 + index(rng, 8))
                    .map(|_| char::from(b' ' + index(rng, 95) as u8))
                    .collect();
                text.insert_str(at, &garbage);
            }
            return (text, None);
        }
    }
    (out.join("\n"), target)
}
