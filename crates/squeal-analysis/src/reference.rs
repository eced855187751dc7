//! Reference values from the source paper, with their provenance.

/// Table 2 of the paper ("Disc FE frequencies"): the disc's normal modes with a free
/// contact surface up to about 10 kHz, as `(label, frequency in Hz, doublet)`.
/// Transcribed in `shared/paper/paper-data.toml` (`[[disc_modes]]`).
pub const TABLE2: [(&str, f64, bool); 16] = [
    ("a,0,0", 892.3, false),
    ("a,0,1", 912.2, true),
    ("a,0,2", 1261.0, true),
    ("a,0,3", 2220.0, true),
    ("c,0", 3108.0, false),
    ("c,1", 3324.0, true),
    ("a,0,4", 3694.0, true),
    ("r,2", 4735.0, true),
    ("a,0,5", 5571.0, true),
    ("a,0,6", 7776.0, true),
    ("a,1,0", 7873.0, false),
    ("a,1,1", 8596.0, true),
    ("r,3", 8634.0, true),
    ("r,0", 9122.0, false),
    ("a,1,2", 9648.0, true),
    ("a,0,7", 10250.0, true),
];
