//! The numbers the documentation states about the embedded scenes are the ones the code
//! builds: the scene tables of `docs/scenes.md` and `README.md`
//! (`| `name` | DOFs | pairs |`) against `squeal scene info`'s model.

use squeal::scene::{build, BodyKind, Scene, BUILTIN_SCENES};

fn number(cell: &str) -> usize {
    cell.trim()
        .replace(',', "")
        .parse()
        .unwrap_or_else(|_| panic!("`{cell}` is not a number"))
}

#[test]
fn the_scene_table_matches_the_built_scenes() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let reg = squeal::registry();
    let models: Vec<_> = BUILTIN_SCENES
        .iter()
        .map(|name| build(&Scene::builtin(name).unwrap(), BodyKind::All, &reg, name).unwrap())
        .collect();
    for file in ["docs/scenes.md", "README.md"] {
        let doc = std::fs::read_to_string(root.join(file)).unwrap();
        for (name, model) in BUILTIN_SCENES.iter().zip(&models) {
            check_row(file, &doc, name, model);
        }
    }
}

fn check_row(file: &str, doc: &str, name: &str, model: &squeal::scene::Model) {
    let row = doc
        .lines()
        .find(|l| l.starts_with(&format!("| `{name}` |")))
        .unwrap_or_else(|| panic!("{file} has no table row for `{name}`"));
    let cells: Vec<&str> = row.split('|').collect();
    assert_eq!(
        number(cells[2]),
        model.dofs.n_free(),
        "{file}, {name}: DOFs in {row}"
    );
    let pairs = model.contact.as_ref().map_or(0, |c| c.len());
    assert_eq!(number(cells[3]), pairs, "{file}, {name}: pairs in {row}");
}

/// The documents a user reads speak of the project as it is: no run labels, issue numbers
/// or history marks (git keeps the history).
#[test]
fn the_documentation_carries_no_history_marks() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = vec![
        root.join("README.md"),
        root.join("ARCHITECTURE.md"),
        root.join("benches/README.md"),
    ];
    for e in std::fs::read_dir(root.join("docs")).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "md") {
            files.push(p);
        }
    }
    let marks = ["session", "previous rig", "issue #", "issue 1", "issue 2"];
    let mut found = Vec::new();
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap().to_lowercase();
        for (i, line) in text.lines().enumerate() {
            for m in marks {
                if line.contains(m) {
                    found.push(format!("{}:{}: `{m}`", f.display(), i + 1));
                }
            }
        }
    }
    assert!(files.len() >= 5, "only {} documents found", files.len());
    assert!(found.is_empty(), "history marks: {}", found.join("; "));
}
