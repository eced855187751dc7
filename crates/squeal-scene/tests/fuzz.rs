//! Property tests of the scene reader: arbitrary text, and the embedded scenes cut or
//! corrupted at random, give a scene or an error naming the file, never a panic.

use proptest::prelude::*;
use squeal_scene::Scene;

fn read(text: &str) -> String {
    match Scene::from_toml(text, "fuzz.toml") {
        Ok(s) => format!("scene {}", s.name),
        Err(e) => e.to_string(),
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn arbitrary_text_never_panics(text in ".{0,300}") {
        let r = read(&text);
        prop_assert!(r.starts_with("scene ") || r.contains("fuzz.toml"), "{}", r);
    }

    #[test]
    fn a_scene_cut_or_corrupted(cut in 0usize..3000, at in 0usize..3000, c in proptest::char::range(' ', '~')) {
        let full = Scene::builtin("pin-on-disc").unwrap().to_toml();
        let cut = cut.min(full.len());
        let mut text: Vec<char> = full[..cut].chars().collect();
        if at < text.len() {
            text[at] = c;
        }
        let text: String = text.into_iter().collect();
        let r = read(&text);
        prop_assert!(r.starts_with("scene ") || r.contains("fuzz.toml"), "{}", r);
    }
}
