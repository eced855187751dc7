//! Unit tests of the pure parts of studies: list parsing, shards, seeds, case ids, input
//! checks, classes and the record format.

use super::*;

/// A square `n x n` contact grid on a face of `size` (m).
fn grid(n: usize, size: f64) -> GridInfo {
    let h = size / (n - 1) as f64;
    let mut points_m = Vec::new();
    for j in 0..n {
        for i in 0..n {
            points_m.push([i as f64 * h, j as f64 * h]);
        }
    }
    GridInfo {
        face_m: [size, size],
        n: [n, n],
        spacing_m: [h, h],
        points_m,
    }
}

fn solve() -> SolveSpec {
    SolveSpec {
        basis: "modes".into(),
        basis_params: Vec::new(),
        eigen: "dense".into(),
        modal: "arpack".into(),
        band_hz: [0.0, 5000.0],
        tol: 1e-10,
        dvr_margin: 0.0,
        classes_hz: vec![2100.0, 3500.0],
        class_width: 0.2,
    }
}

fn def(study: StudySpec) -> StudyDef {
    StudyDef {
        version: "test".into(),
        scene: "<test>".into(),
        scene_toml: String::new(),
        dofs: 100,
        rotation: 1.0,
        damping: Default::default(),
        grid: grid(21, 0.020),
        study,
        solve: solve(),
    }
}

fn macro_spec(x0: Axis, y0: Axis, a: Vec<f64>, b: Vec<f64>) -> StudySpec {
    StudySpec::Macro(MacroSpec {
        mu: vec![0.36, 0.43],
        x0,
        y0,
        a_m: a,
        b_m: b,
    })
}

fn meso_spec(patch: Vec<f64>) -> StudySpec {
    StudySpec::Meso(MesoSpec {
        mu: vec![0.36],
        region_m: [0.010, 0.003, 0.008, 0.014],
        patch_m: patch,
        layouts: 5,
        fraction: 0.5,
        seed: 7,
    })
}

fn message(e: StudyError) -> String {
    e.to_string()
}

#[test]
fn lists_take_values_and_ranges_in_order() {
    assert_eq!(parse_list("--a", "0.1").unwrap(), vec![0.1]);
    assert_eq!(
        parse_list("--a", "0.004:0.01:0.002, 0.02").unwrap(),
        vec![0.004, 0.006, 0.008, 0.01, 0.02]
    );
    // the end is included despite round-off in the step, and values are rounded
    let v = parse_list("--mu", "0:0.3:0.1").unwrap();
    assert_eq!(v, vec![0.0, 0.1, 0.2, 0.3]);
    assert_eq!(parse_list("--a", "1:1:0.5").unwrap(), vec![1.0]);
}

#[test]
fn bad_lists_name_the_option_and_the_form() {
    for bad in [
        "", "0.1,", "x", "1:2", "2:1:0.5", "1:2:0", "1:2:-1", "1:2:3:4", "nan", "inf",
    ] {
        let e = message(parse_list("--patch", bad).unwrap_err());
        assert!(e.starts_with("--patch: "), "{bad:?}: {e}");
    }
    let e = message(parse_list("--a", "2:1:0.5").unwrap_err());
    assert!(e.contains("FROM:TO:STEP"), "{e}");
    let e = message(parse_list("--a", "0:1:1e-9").unwrap_err());
    assert!(e.contains("at most"), "{e}");
}

#[test]
fn axes_are_centred_or_non_negative_offsets() {
    assert_eq!(Axis::parse("--x0", "centred").unwrap(), Axis::Centred);
    assert_eq!(Axis::parse("--x0", "center").unwrap(), Axis::Centred);
    assert_eq!(
        Axis::parse("--x0", "0:0.002:0.001").unwrap(),
        Axis::Values(vec![0.0, 0.001, 0.002])
    );
    let e = message(Axis::parse("--y0", "-0.001").unwrap_err());
    assert!(e.starts_with("--y0: ") && e.contains(">= 0"), "{e}");
    assert_eq!(Axis::Centred.offsets(0.02, 0.008), vec![0.006]);
}

#[test]
fn shards_split_every_case_exactly_once() {
    for n in 1..6 {
        let shards: Vec<Shard> = (1..=n)
            .map(|k| Shard::parse(&format!("{k}/{n}")).unwrap())
            .collect();
        for i in 0..37 {
            assert_eq!(
                shards.iter().filter(|s| s.holds(i)).count(),
                1,
                "{i} in {n}"
            );
        }
        // balanced: sizes differ by at most one
        let sizes: Vec<usize> = shards
            .iter()
            .map(|s| (0..37).filter(|&i| s.holds(i)).count())
            .collect();
        assert!(sizes.iter().max().unwrap() - sizes.iter().min().unwrap() <= 1);
    }
    assert_eq!(Shard::parse(" 2 / 3 ").unwrap(), Shard { k: 2, n: 3 });
    for bad in ["0/2", "3/2", "1/0", "2", "a/b", "1/2/3", "-1/2", ""] {
        let e = message(Shard::parse(bad).unwrap_err());
        assert!(
            e.starts_with("options.shard: ") && e.contains("K/N"),
            "{bad:?}: {e}"
        );
    }
}

#[test]
fn regions_need_four_values() {
    assert_eq!(
        parse_region("--region", "0.01,0.003,0.008,0.014").unwrap(),
        [0.01, 0.003, 0.008, 0.014]
    );
    for bad in [
        "0.01,0.003,0.008",
        "0,0,0,0.01",
        "-0.001,0,0.01,0.01",
        "a,b,c,d",
    ] {
        let e = message(parse_region("--region", bad).unwrap_err());
        assert!(e.starts_with("--region: "), "{bad:?}: {e}");
    }
}

#[test]
fn seeds_are_stable_and_distinct() {
    // fixed values (an independent splitmix64 in Python): a change here changes every
    // layout of every stored study
    assert_eq!(derive_seed(0, 400, 0), 8_959_770_944_897_836_669);
    assert_eq!(derive_seed(42, 1000, 17), 2_409_746_963_340_271_505);
    let mut seen = std::collections::BTreeSet::new();
    for base in [0u64, 1, 42] {
        for p in [400u64, 600, 800, 1000] {
            for l in 0..200 {
                assert!(seen.insert(derive_seed(base, p, l)), "{base} {p} {l}");
            }
        }
    }
    // a layout depends on its patch size, not on the position in the patch list
    let a = def(meso_spec(vec![0.001, 0.002])).cases().unwrap();
    let b = def(meso_spec(vec![0.002])).cases().unwrap();
    let zone = |l: &CaseList, id: &str| l.cases.iter().find(|c| c.id == id).unwrap().zone.clone();
    assert_eq!(
        zone(&a, "mu03600-p002000-l00003"),
        zone(&b, "mu03600-p002000-l00003")
    );
}

#[test]
fn macro_cases_have_stable_sorted_ids() {
    let d = def(macro_spec(
        Axis::Centred,
        Axis::Centred,
        vec![0.004, 0.012],
        vec![0.0142],
    ));
    let list = d.cases().unwrap();
    let ids: Vec<&str> = list.cases.iter().map(|c| c.id.as_str()).collect();
    assert_eq!(
        ids,
        [
            "mu03600-x004000-y002900-a012000-b014200",
            "mu03600-x008000-y002900-a004000-b014200",
            "mu04300-x004000-y002900-a012000-b014200",
            "mu04300-x008000-y002900-a004000-b014200",
        ]
    );
    let c = &list.cases[0];
    // x in [4, 16] mm: 13 columns; y in [2.9, 17.1] mm: rows 3..=17
    assert_eq!(c.pairs, 13 * 15);
    assert!((c.area_m2 - 0.012 * 0.0142).abs() < 1e-15);
    // the same definition gives the same list
    assert_eq!(d.cases().unwrap(), list);
}

#[test]
fn macro_grids_skip_combinations_that_leave_the_face() {
    let d = def(macro_spec(
        Axis::Values(vec![0.0, 0.010]),
        Axis::Values(vec![0.0]),
        vec![0.008, 0.012],
        vec![0.010],
    ));
    let list = d.cases().unwrap();
    // x0 = 10 mm + a = 12 mm leaves the face: skipped for both mu
    assert_eq!(list.cases.len(), 6);
    assert_eq!(list.skipped.outside_face, 2);
    assert!(d.warnings(&list).iter().any(|w| w.contains("do not fit")));
}

#[test]
fn zones_outside_the_face_are_errors_naming_the_option() {
    let cases = |x0: Axis, a: Vec<f64>| def(macro_spec(x0, Axis::Centred, a, vec![0.01])).cases();
    let e = message(cases(Axis::Centred, vec![0.025]).unwrap_err());
    assert!(
        e.starts_with("study.a_m: ") && e.contains("(0, 0.02]"),
        "{e}"
    );
    let e = message(cases(Axis::Values(vec![0.0, 0.019]), vec![0.004]).unwrap_err());
    assert!(
        e.starts_with("study.x0: ") && e.contains("[0, 0.016]"),
        "{e}"
    );
    let e = message(cases(Axis::Values(vec![0.005]), vec![0.004, 0.018]).unwrap_err());
    assert!(
        e.starts_with("study.a_m: ") && e.contains("<= 0.015"),
        "{e}"
    );
    let e = message(
        def(macro_spec(
            Axis::Centred,
            Axis::Values(vec![0.021]),
            vec![0.01],
            vec![0.001],
        ))
        .cases()
        .unwrap_err(),
    );
    assert!(e.starts_with("study.y0: "), "{e}");
    let e = message(cases(Axis::Centred, vec![0.0]).unwrap_err());
    assert!(e.starts_with("study.a_m: ") && e.contains("> 0"), "{e}");
    let mut d = def(macro_spec(
        Axis::Centred,
        Axis::Centred,
        vec![0.01],
        vec![0.01],
    ));
    if let StudySpec::Macro(s) = &mut d.study {
        s.mu = vec![-0.1];
    }
    assert!(message(d.cases().unwrap_err()).starts_with("study.mu: "));
    if let StudySpec::Macro(s) = &mut d.study {
        s.mu = vec![0.36, 0.36];
    }
    let e = message(d.cases().unwrap_err());
    assert!(e.contains("same id"), "{e}");
}

#[test]
fn meso_cases_are_seeded_layouts_inside_the_region() {
    let d = def(meso_spec(vec![0.001, 0.002]));
    let list = d.cases().unwrap();
    assert_eq!(list.cases.len(), 10);
    assert_eq!(list.cases[0].id, "mu03600-p001000-l00000");
    assert_eq!(list.cases[9].id, "mu03600-p002000-l00004");
    for c in &list.cases {
        let sel = c.zone.select(&d.grid.points_m, d.grid.face_m);
        for (p, &on) in d.grid.points_m.iter().zip(&sel) {
            if on {
                assert!(p[0] >= 0.010 - 1e-12 && p[0] <= 0.018 + 1e-12, "{p:?}");
                assert!(p[1] >= 0.003 - 1e-12 && p[1] <= 0.017 + 1e-12, "{p:?}");
            }
        }
        assert_eq!(sel.iter().filter(|&&b| b).count(), c.pairs);
        // half of the patches: area = fraction of the region
        assert!(
            (c.area_m2 - 0.5 * 0.008 * 0.014).abs() < 1e-4 * c.area_m2,
            "{}",
            c.area_m2
        );
    }
    // layouts differ from one another
    assert_ne!(list.cases[0].zone, list.cases[1].zone);
}

#[test]
fn bad_meso_inputs_name_the_option_and_the_expected_value() {
    let e = message(def(meso_spec(vec![0.0004])).cases().unwrap_err());
    assert!(
        e.starts_with("study.patch_m: ")
            && e.contains("contact grid spacing")
            && e.contains(">= 1.000 mm"),
        "{e}"
    );
    let e = message(def(meso_spec(vec![0.009])).cases().unwrap_err());
    assert!(
        e.starts_with("study.patch_m: ") && e.contains("<= 0.008 m"),
        "{e}"
    );
    let mut d = def(meso_spec(vec![0.001]));
    if let StudySpec::Meso(s) = &mut d.study {
        s.region_m = [0.015, 0.0, 0.008, 0.01];
    }
    assert!(message(d.cases().unwrap_err()).starts_with("study.region_m: "));
    if let StudySpec::Meso(s) = &mut d.study {
        s.region_m = [0.0, 0.0, 0.008, 0.01];
        s.fraction = 0.0;
    }
    assert!(message(d.cases().unwrap_err()).starts_with("study.fraction: "));
    if let StudySpec::Meso(s) = &mut d.study {
        s.fraction = 0.5;
        s.layouts = 0;
    }
    assert!(message(d.cases().unwrap_err()).starts_with("study.layouts: "));
}

#[test]
fn classes_have_a_window() {
    let s = solve();
    assert_eq!(s.class_of(2150.0), Some(2100.0));
    assert_eq!(s.class_of(3300.0), Some(3500.0));
    assert_eq!(s.class_of(6000.0), None);
    assert_eq!(s.class_of(1000.0), None);
    s.check().unwrap();
    let mut bad = solve();
    bad.band_hz = [5000.0, 100.0];
    assert!(message(bad.check().unwrap_err()).starts_with("solve.band_hz: "));
    let mut bad = solve();
    bad.class_width = 1.5;
    assert!(message(bad.check().unwrap_err()).starts_with("solve.class_width: "));
}

#[test]
fn records_round_trip_through_a_json_line() {
    let d = def(meso_spec(vec![0.002]));
    let case = d.cases().unwrap().cases[0].clone();
    let rec = Record {
        case,
        basis_size: 12,
        unstable: vec![UnstableMode {
            freq_hz: 2101.5,
            dvr: 0.0123,
            backward_error: 1e-12,
            class_hz: Some(2100.0),
        }],
        neutral: vec![[900.0, -1e-9]],
        modes: vec![[900.0, -1e-9], [2101.5, 0.0123]],
        max_backward_error: 1e-12,
        error: None,
    };
    let line = serde_json::to_string(&rec).unwrap();
    assert!(!line.contains('\n'));
    let back: Record = serde_json::from_str(&line).unwrap();
    assert_eq!(back, rec);
    assert_eq!(serde_json::to_string(&back).unwrap(), line);
}

#[test]
fn summaries_count_classes_per_group() {
    let d = def(macro_spec(
        Axis::Centred,
        Axis::Centred,
        vec![0.004, 0.012],
        vec![0.0142],
    ));
    let list = d.cases().unwrap();
    let mode = |f: f64| UnstableMode {
        freq_hz: f,
        dvr: 0.01,
        backward_error: 1e-12,
        class_hz: d.solve.class_of(f),
    };
    let records: Vec<Record> = list
        .cases
        .iter()
        .zip([
            vec![mode(2100.0)],
            vec![],
            vec![mode(3400.0), mode(7000.0)],
            vec![],
        ])
        .map(|(c, unstable)| Record {
            case: c.clone(),
            basis_size: 10,
            unstable,
            modes: Vec::new(),
            max_backward_error: 0.0,
            error: None,
            neutral: Vec::new(),
        })
        .collect();
    let s = summarize(&d, &list, &records);
    assert!(s.complete);
    assert_eq!(s.unstable_cases, 2);
    assert_eq!(s.by_mu.len(), 2);
    assert_eq!(s.by_mu[0].classes[0].cases, 1);
    assert_eq!(s.by_mu[0].classes[0].unstable_fraction, 0.5);
    assert_eq!(s.by_mu[0].classes[0].unstable_ci95, wilson95(1, 2));
    assert_eq!(s.unstable_ci95, wilson95(2, 4));
    assert_eq!(s.by_mu[0].classes[1].cases, 0);
    assert_eq!(s.by_mu[1].classes[1].cases, 1);
    assert_eq!(s.by_mu[1].unclassified, 1);
    assert_eq!(s.by_mu[0].classes[0].zones_m.len(), 1);
    // a partial set of records is not complete
    let s = summarize(&d, &list, &records[..3]);
    assert!(!s.complete);
    assert_eq!(s.cases_done, 3);
}

#[test]
fn wilson_intervals_match_published_values_and_stay_in_the_unit_interval() {
    // Newcombe (1998), Table I: 81/263 -> 0.2553-0.3662; 15/148 -> 0.0624-0.1605
    let [lo, hi] = wilson95(81, 263);
    assert!(
        (lo - 0.2553).abs() < 5e-5 && (hi - 0.3662).abs() < 5e-5,
        "{lo} {hi}"
    );
    let [lo, hi] = wilson95(15, 148);
    assert!(
        (lo - 0.0624).abs() < 5e-5 && (hi - 0.1605).abs() < 5e-5,
        "{lo} {hi}"
    );
    // the ends: not empty, inside [0, 1]; 0/10 -> 0-0.2775
    let [lo, hi] = wilson95(0, 10);
    assert!(lo == 0.0 && (hi - 0.2775).abs() < 5e-5, "{lo} {hi}");
    let [lo, hi] = wilson95(10, 10);
    assert!(hi == 1.0 && (lo - 0.7225).abs() < 5e-5, "{lo} {hi}");
    assert_eq!(wilson95(0, 0), [0.0, 1.0]);
}

/// A 20 mm face with 1 mm lines and 0.2 mm lines over x in [10, 20] mm, y in [4, 18] mm
/// (a contact refinement).
fn refined_grid() -> GridInfo {
    let lines = |lo: f64, hi: f64| -> Vec<f64> {
        let mut v: Vec<f64> = (0..=20)
            .map(|i| i as f64 * 1e-3)
            .filter(|&x| x < lo - 1e-9 || x > hi + 1e-9)
            .collect();
        v.extend((0..=((hi - lo) / 2e-4).round() as usize).map(|i| lo + i as f64 * 2e-4));
        v.sort_by(f64::total_cmp);
        v
    };
    let (xs, ys) = (lines(0.010, 0.020), lines(0.004, 0.018));
    let points_m = ys
        .iter()
        .flat_map(|&y| xs.iter().map(move |&x| [x, y]))
        .collect();
    GridInfo {
        face_m: [0.02, 0.02],
        n: [xs.len(), ys.len()],
        spacing_m: [1e-3, 1e-3],
        points_m,
    }
}

#[test]
fn grid_cells_tile_the_face_and_follow_the_refinement() {
    for g in [grid(5, 0.02), refined_grid()] {
        let cells = g.cells_m();
        assert_eq!(cells.len(), g.points_m.len());
        let mut area = 0.0;
        for (c, p) in cells.iter().zip(&g.points_m) {
            assert!(c[0] <= p[0] && p[0] <= c[1] && c[2] <= p[1] && p[1] <= c[3]);
            assert!(c[0] < c[1] && c[2] < c[3], "{c:?}");
            area += (c[1] - c[0]) * (c[3] - c[2]);
        }
        let face = g.face_m[0] * g.face_m[1];
        assert!((area - face).abs() < 1e-12 * face, "{area} vs {face}");
    }
    // inside the refined band a cell is 0.2 mm wide, outside 1 mm, half at the face edge
    let g = refined_grid();
    let cells = g.cells_m();
    let width = |x: f64| {
        let k = g
            .points_m
            .iter()
            .position(|p| (p[0] - x).abs() < 1e-12)
            .unwrap();
        cells[k][1] - cells[k][0]
    };
    assert!((width(0.015) - 2e-4).abs() < 1e-12);
    assert!((width(0.005) - 1e-3).abs() < 1e-12);
    assert!((width(0.0) - 5e-4).abs() < 1e-12);
}

#[test]
fn meso_patches_follow_the_grid_spacing_inside_their_region() {
    let g = refined_grid();
    let fine = g.spacing_in([0.010, 0.004, 0.010, 0.014]);
    assert!(
        (fine[0] - 2e-4).abs() < 1e-12 && (fine[1] - 2e-4).abs() < 1e-12,
        "{fine:?}"
    );
    // a region reaching past the fine band sees the coarse step
    let wide = g.spacing_in([0.009, 0.004, 0.011, 0.014]);
    assert!((wide[0] - 1e-3).abs() < 1e-12, "{wide:?}");
    let mut d = def(meso_spec(vec![0.0004, 0.0016]));
    d.grid = g.clone();
    if let StudySpec::Meso(s) = &mut d.study {
        s.region_m = [0.010, 0.004, 0.010, 0.014];
        s.layouts = 3;
    }
    let list = d.cases().expect("0.4 mm patches on the 0.2 mm region");
    // a 0.4 mm patch holds 3 x 3 pairs (its edges on grid lines), half the patches in
    // contact: about half the region's 51 x 71 pairs
    let small: Vec<&Case> = list
        .cases
        .iter()
        .filter(|c| c.patch_m == Some(0.0004))
        .collect();
    assert_eq!(small.len(), 3);
    for c in &small {
        assert!((1200..=2700).contains(&c.pairs), "{} pairs", c.pairs);
    }
    if let StudySpec::Meso(s) = &mut d.study {
        s.region_m = [0.0, 0.004, 0.010, 0.014];
    }
    let e = message(d.cases().unwrap_err());
    assert!(
        e.starts_with("study.patch_m: ")
            && e.contains(">= 1.000 mm")
            && e.contains("contact_refinement"),
        "{e}"
    );
}
