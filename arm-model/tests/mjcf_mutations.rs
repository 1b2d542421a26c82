//! The MJCF reader on damaged files: thousands of seeded mutations of
//! real MJCF arms (cut short, spans dropped or doubled, numbers replaced
//! by extreme or non-finite ones, attributes renamed) each give a model or
//! an error, never a panic (#47; the cargo-fuzz target `mjcf` searches
//! further, fuzz/README.md).

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

use std::path::Path;

use arm_model::ArmModel;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const SEEDS: [&str; 5] = [
    "arm-model/tests/data/two_link_hinge.xml",
    "arm-model/tests/data/geom_inertia.xml",
    "arm-model/tests/data/slide_armature.xml",
    "arm-model/tests/data/free_joint.xml",
    "robots/menagerie/universal_robots_ur5e/ur5e.xml",
];

const MUTATIONS: usize = 400;

const NUMBERS: [&str; 8] = ["nan", "inf", "-inf", "1e308", "-1e308", "0", "-0", "1e-320"];
const ATTRIBUTES: [&str; 10] = [
    "type=\"ball\"",
    "type=\"free\"",
    "type=\"slide\"",
    "limited=\"true\"",
    "range=\"5 -5\"",
    "actuatorfrcrange=\"nan 1\"",
    "class=\"missing\"",
    "mass=\"-1\"",
    "quat=\"0 0 0 0\"",
    "fromto=\"0 0 0 0 0 0\"",
];

/// A char boundary at or before `i`.
fn boundary(text: &str, mut i: usize) -> usize {
    i = i.min(text.len());
    while !text.is_char_boundary(i) {
        i -= 1;
    }
    i
}

fn mutate(text: &str, rng: &mut ChaCha8Rng) -> String {
    let n = text.len();
    let a = boundary(text, rng.random_range(0..=n));
    let b = boundary(text, (a + rng.random_range(0..200)).min(n));
    match rng.random_range(0..5) {
        0 => text[..a].to_string(),
        1 => format!("{}{}", &text[..a], &text[b..]),
        2 => format!("{}{}{}", &text[..b], &text[a..b], &text[b..]),
        3 => {
            // Replace the next number after `a`.
            let rest = &text[a..];
            match rest.find(|c: char| c.is_ascii_digit()) {
                Some(s) => {
                    let s = a + s;
                    let e = text[s..]
                        .find(|c: char| !(c.is_ascii_digit() || c == '.' || c == 'e' || c == '-'))
                        .map_or(n, |e| s + e);
                    let x = NUMBERS[rng.random_range(0..NUMBERS.len())];
                    format!("{}{x}{}", &text[..s], &text[e..])
                }
                None => text.to_string(),
            }
        }
        _ => {
            // An attribute put into the next tag after `a`.
            match text[a..].find('<') {
                Some(s) => {
                    let s = a + s;
                    let e = text[s..].find([' ', '>']).map_or(n, |e| s + e);
                    let x = ATTRIBUTES[rng.random_range(0..ATTRIBUTES.len())];
                    format!("{} {x} {}", &text[..e], &text[e..])
                }
                None => text.to_string(),
            }
        }
    }
}

#[test]
fn damaged_mjcf_gives_a_model_or_an_error_never_a_panic() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut rng = ChaCha8Rng::seed_from_u64(47);
    let (mut read, mut refused) = (0, 0);
    for seed in SEEDS {
        let text = std::fs::read_to_string(root.join(seed)).unwrap();
        for _ in 0..MUTATIONS {
            let mut damaged = mutate(&text, &mut rng);
            if rng.random_bool(0.3) {
                damaged = mutate(&damaged, &mut rng);
            }
            match std::panic::catch_unwind(|| ArmModel::from_urdf_str(&damaged)) {
                Ok(Ok(_)) => read += 1,
                Ok(Err(e)) => {
                    assert!(!e.to_string().is_empty());
                    refused += 1;
                }
                Err(_) => panic!("{seed}: the reader panicked on:\n{damaged}"),
            }
        }
    }
    // Both outcomes occur, so the mutations reach past the first check.
    assert!(read > 0 && refused > 0, "read {read}, refused {refused}");
}
