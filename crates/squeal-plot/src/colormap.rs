//! The colour scale of the maps.

use plotters::style::RGBColor;

/// Viridis colormap (9 reference colours, linear interpolation), `t` clamped to [0, 1].
pub(crate) fn viridis(t: f64) -> RGBColor {
    const C: [(f64, f64, f64); 9] = [
        (68.0, 1.0, 84.0),
        (72.0, 40.0, 120.0),
        (62.0, 73.0, 137.0),
        (49.0, 104.0, 142.0),
        (38.0, 130.0, 142.0),
        (31.0, 158.0, 137.0),
        (53.0, 183.0, 121.0),
        (110.0, 206.0, 88.0),
        (253.0, 231.0, 37.0),
    ];
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let s = t * (C.len() - 1) as f64;
    let i = (s.floor() as usize).min(C.len() - 2);
    let f = s - i as f64;
    let lerp = |a: f64, b: f64| (a + f * (b - a)).round() as u8;
    RGBColor(
        lerp(C[i].0, C[i + 1].0),
        lerp(C[i].1, C[i + 1].1),
        lerp(C[i].2, C[i + 1].2),
    )
}
