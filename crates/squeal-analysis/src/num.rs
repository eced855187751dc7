//! Number formatting for printed tables, reports and CSV files: a value that prints as
//! zero prints without a sign (`0.0000`, `0.000000e0`), whether it is a negative zero
//! (an undamped mode's real part) or a tiny negative value rounded away.

/// `x` with `prec` decimals (`{:.prec$}`), unsigned when it reads as zero.
pub fn fixed(x: f64, prec: usize) -> String {
    unsigned_zero(format!("{x:.prec$}"))
}

/// `x` in scientific notation with `prec` decimals (`{:.prec$e}`), unsigned when it
/// reads as zero.
pub fn sci(x: f64, prec: usize) -> String {
    unsigned_zero(format!("{x:.prec$e}"))
}

/// Drops the minus sign of a formatted number whose digits are all zero.
fn unsigned_zero(s: String) -> String {
    let mantissa = s.split(['e', 'E']).next().unwrap_or("");
    if s.starts_with('-') && mantissa.chars().all(|c| matches!(c, '-' | '0' | '.')) {
        s[1..].to_string()
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::{fixed, sci};

    #[test]
    fn zeros_print_unsigned() {
        assert_eq!(sci(-0.0, 6), "0.000000e0");
        assert_eq!(sci(-0.0, 4), "0.0000e0");
        assert_eq!(fixed(-0.0, 4), "0.0000");
        assert_eq!(fixed(-1e-19, 4), "0.0000");
        assert_eq!(fixed(-1e-19, 0), "0");
        // real negative values keep their sign
        assert_eq!(sci(-5.3e-11, 6), "-5.300000e-11");
        assert_eq!(sci(-1e-300, 2), "-1.00e-300");
        assert_eq!(fixed(-0.00051, 3), "-0.001");
        assert_eq!(fixed(-2.5, 1), "-2.5");
        assert_eq!(sci(0.0, 3), "0.000e0");
    }
}
