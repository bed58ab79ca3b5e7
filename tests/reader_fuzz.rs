//! Mutation fuzzing of the readers built on third-party crates: USD text
//! (`.usda`) and glTF (`.glb`). Each case changes the shared fixtures a
//! little (tokens, JSON values) and reads the result: a groom or character
//! that holds its invariants, or a typed file error naming the problem —
//! never a panic, an abort or a hang (the case count is small and the seed
//! fixed, so CI runs the same cases every time; raise `PROPTEST_CASES` to
//! search further).
//!
//! USD binary (`.usdc`) is mutated byte by byte (any byte of the file to one
//! of a few telling values): the USD library sizes its tables and value
//! arrays by counts it reads from the file, and an unchecked count asked it
//! for up to 9 × 10¹⁸ bytes, which aborts the process (no panic to catch);
//! `groom::usdc_check` and its value checks bound them first.

use std::path::{Path, PathBuf};

use proptest::prelude::*;
use proptest::test_runner::{RngSeed, TestCaseError};
use vkhair::character::Character;
use vkhair::groom::usd;
use vkhair::Error;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

/// A fixed seed, `cases` cases (or `PROPTEST_CASES`).
fn config(cases: u32) -> ProptestConfig {
    let cases = std::env::var("PROPTEST_CASES").ok().and_then(|c| c.parse().ok()).unwrap_or(cases);
    ProptestConfig {
        cases,
        rng_seed: RngSeed::Fixed(0x766b_6861_6972),
        failure_persistence: None,
        ..Default::default()
    }
}

/// A reader's result: a groom with at least one strand of finite points, or
/// an error that names what is wrong (no empty message, no internal panic
/// text without the reader's words).
fn check_usd(
    result: vkhair::Result<(vkhair::groom::authored::AuthoredGroom, vkhair::groom::Repairs)>,
) -> Result<(), TestCaseError> {
    match result {
        Ok((g, _)) => {
            prop_assert!(g.groom.strand_count() > 0);
            prop_assert!(g.groom.positions().iter().all(|p| p.is_finite()));
        }
        Err(e) => {
            let text = e.to_string();
            prop_assert!(matches!(e, Error::Asset { .. }), "not a file error: {e:?}");
            prop_assert!(!text.is_empty());
        }
    }
    Ok(())
}

/// Reads `bytes` as the USD layer `name` (strict and repairing).
fn read_usd(name: &str, bytes: &[u8]) -> Result<(), TestCaseError> {
    let dir = tempfile::tempdir().map_err(|e| TestCaseError::fail(e.to_string()))?;
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).map_err(|e| TestCaseError::fail(e.to_string()))?;
    check_usd(usd::open_repairing(&path))?;
    check_usd(usd::open(&path).map(|g| (g, Default::default())))
}

/// Tokens a `.usda` mutation writes in place of a word.
const USDA_TOKENS: [&str; 16] =
    ["nan", "inf", "-1", "0", "1e39", "4294967296", "[", "]", "{", "}", "(", ")", "</a>", "@x.usda@", "\"", "def"];

proptest! {
    #![proptest_config(config(48))]

    #[test]
    fn mutated_usda_files_give_grooms_or_file_errors(
        changes in prop::collection::vec((any::<prop::sample::Index>(), prop::sample::select(USDA_TOKENS.to_vec())), 1..3),
    ) {
        let text = std::fs::read_to_string(data("usd/small_cm_zup.usda")).expect("fixture");
        let mut words: Vec<String> = text.split(' ').map(str::to_owned).collect();
        for (at, token) in &changes {
            let i = at.index(words.len());
            words[i] = (*token).to_owned();
        }
        read_usd("mutated.usda", words.join(" ").as_bytes())?;
    }

    #[test]
    fn mutated_gltf_documents_give_characters_or_file_errors(
        changes in prop::collection::vec((any::<prop::sample::Index>(), prop::sample::select(vec![
            serde_json::json!(0), serde_json::json!(-1), serde_json::json!(9999), serde_json::json!(4294967296u64),
            serde_json::json!(1e30), serde_json::json!("x"), serde_json::json!([]), serde_json::json!(null),
        ])), 1..3),
    ) {
        let bytes = std::fs::read(data("mannequiny-0.3.0.glb")).expect("fixture");
        let json_len = u32::from_le_bytes(bytes[12..16].try_into().expect("length")) as usize;
        let mut json: serde_json::Value = serde_json::from_slice(&bytes[20..20 + json_len]).expect("json");
        // Every number in the document, by a path to it.
        let mut numbers = Vec::new();
        collect_numbers(&json, &mut Vec::new(), &mut numbers);
        for (at, value) in &changes {
            let path = &numbers[at.index(numbers.len())];
            if let Some(slot) = pointer_mut(&mut json, path) {
                *slot = value.clone();
            }
        }
        let mut text = serde_json::to_vec(&json).expect("json");
        while !text.len().is_multiple_of(4) {
            text.push(b' ');
        }
        let rest = &bytes[20 + json_len..];
        let mut glb = Vec::new();
        glb.extend_from_slice(&bytes[0..8]);
        glb.extend_from_slice(&((12 + 8 + text.len() + rest.len()) as u32).to_le_bytes());
        glb.extend_from_slice(&(text.len() as u32).to_le_bytes());
        glb.extend_from_slice(b"JSON");
        glb.extend_from_slice(&text);
        glb.extend_from_slice(rest);
        match Character::parse(&glb) {
            Ok(c) => prop_assert!(c.positions.iter().all(|p| p.is_finite())),
            Err(e) => prop_assert!(!e.to_string().is_empty()),
        }
    }
}

proptest! {
    #![proptest_config(config(400))]

    #[test]
    fn mutated_usdc_files_give_grooms_or_file_errors(
        changes in prop::collection::vec(
            (any::<prop::sample::Index>(), prop::sample::select(vec![0x00u8, 0x01, 0x20, 0x40, 0x7F, 0x80, 0xFF])),
            1..4,
        ),
    ) {
        let mut bytes = std::fs::read(data("usd/small_cm_zup.usdc")).expect("fixture");
        for (at, value) in &changes {
            let i = at.index(bytes.len());
            bytes[i] = *value;
        }
        read_usd("mutated.usdc", &bytes)?;
    }
}

/// The paths (object keys and array indices) of every number under `value`.
fn collect_numbers(value: &serde_json::Value, path: &mut Vec<String>, out: &mut Vec<Vec<String>>) {
    match value {
        serde_json::Value::Number(_) => out.push(path.clone()),
        serde_json::Value::Array(items) => {
            for (i, item) in items.iter().enumerate() {
                path.push(i.to_string());
                collect_numbers(item, path, out);
                path.pop();
            }
        }
        serde_json::Value::Object(map) => {
            for (key, item) in map {
                path.push(key.clone());
                collect_numbers(item, path, out);
                path.pop();
            }
        }
        _ => {}
    }
}

/// The value at `path` under `value`.
fn pointer_mut<'v>(value: &'v mut serde_json::Value, path: &[String]) -> Option<&'v mut serde_json::Value> {
    let pointer: String = path.iter().map(|p| format!("/{}", p.replace('~', "~0").replace('/', "~1"))).collect();
    value.pointer_mut(&pointer)
}
