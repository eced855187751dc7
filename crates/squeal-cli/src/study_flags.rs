//! Study errors in the terms of the command line: the library names the fields of a
//! study's definition (`study.patch_m`), `squeal` names the options that set them
//! (`--patch`).

use squeal_analysis::study::StudyError;

/// The command-line option of each field a study error names (`StudyError::Input`).
const FLAGS: [(&str, &str); 21] = [
    ("study.mu", "--mu"),
    ("study.x0", "--x0"),
    ("study.y0", "--y0"),
    ("study.a_m", "--a"),
    ("study.b_m", "--b"),
    ("study.region_m", "--region"),
    ("study.patch_m", "--patch"),
    ("study.layouts", "--layouts"),
    ("study.fraction", "--fraction"),
    ("solve.band_hz", "--band"),
    ("solve.dvr_margin", "--dvr-margin"),
    ("solve.tol", "--tol"),
    ("solve.classes_hz", "--classes"),
    ("solve.class_width", "--class-width"),
    ("solve.basis_params", "--basis-opt"),
    ("options.shard", "--shard"),
    ("options.jobs", "--jobs"),
    ("options.resume", "--resume"),
    ("dirs", "DIRS"),
    ("dir", "--out"),
    ("scene", "SCENE"),
];

/// A study error with its fields named as the command-line options that set them.
pub fn flags(e: StudyError) -> anyhow::Error {
    match e {
        StudyError::Input { field, message } => {
            let flag = |name: &str| {
                FLAGS
                    .iter()
                    .find(|(f, _)| *f == name)
                    .map_or(name.to_string(), |(_, o)| (*o).to_string())
            };
            let field = field.split('/').map(flag).collect::<Vec<_>>().join("/");
            let message = FLAGS
                .iter()
                .filter(|(f, _)| f.contains('.'))
                .fold(message, |m, (f, o)| m.replace(f, o));
            anyhow::anyhow!("{field}: {message}")
        }
        e => e.into(),
    }
}

#[cfg(test)]
mod tests {
    use super::{flags, StudyError};

    fn input(field: &str, message: &str) -> String {
        flags(StudyError::Input {
            field: field.into(),
            message: message.into(),
        })
        .to_string()
    }

    #[test]
    fn study_fields_are_named_as_their_options() {
        assert_eq!(
            input(
                "study.x0",
                "a zone starting at 0.015 m leaves the face even with the smallest study.a_m \
                 0.01 m: expected study.x0 in [0, 0.01] m"
            ),
            "--x0: a zone starting at 0.015 m leaves the face even with the smallest --a \
             0.01 m: expected --x0 in [0, 0.01] m"
        );
        assert_eq!(
            input("study.mu/study.patch_m", "two cases have the same id"),
            "--mu/--patch: two cases have the same id"
        );
        assert_eq!(
            input(
                "dir",
                "x already holds results: set options.resume to continue"
            ),
            "--out: x already holds results: set --resume to continue"
        );
        assert_eq!(
            input(
                "solve.dvr_margin",
                "expected solve.tol and solve.dvr_margin > 0"
            ),
            "--dvr-margin: expected --tol and --dvr-margin > 0"
        );
        // a field of the scene file is not an option
        assert_eq!(
            input("study.mu", "reverse the scene's study.rotation"),
            "--mu: reverse the scene's study.rotation"
        );
    }
}
