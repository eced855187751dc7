//! The numbers the documentation states about the embedded scenes are the ones the code
//! builds: the table of `docs/scenes.md` (`| `name` | DOFs | pairs |`) against
//! `squeal scene info`'s model.

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
    let doc = std::fs::read_to_string(root.join("docs/scenes.md")).unwrap();
    let reg = squeal::registry();
    for name in BUILTIN_SCENES {
        let row = doc
            .lines()
            .find(|l| l.starts_with(&format!("| `{name}` |")))
            .unwrap_or_else(|| panic!("docs/scenes.md has no table row for `{name}`"));
        let cells: Vec<&str> = row.split('|').collect();
        let model = build(&Scene::builtin(name).unwrap(), BodyKind::All, &reg, name).unwrap();
        assert_eq!(
            number(cells[2]),
            model.dofs.n_free(),
            "{name}: DOFs in {row}"
        );
        let pairs = model.contact.as_ref().map_or(0, |c| c.len());
        assert_eq!(number(cells[3]), pairs, "{name}: pairs in {row}");
    }
}
