//! Numbers from a STEP or QIF file into the written spec, through one function,
//! [`written`]: the text `fmt_num` gives and the value the spec will read back from it.
//!
//! **Decision:** a number is written only when the spec can hold it: finite (the
//! grammar's `number` reads no `inf` or `NaN`, and lowering refuses one past `f64`), at
//! most [`LARGEST`] in size (no part measures a kilometre; the sums resolve makes of
//! limits stay finite), and, where `resolve` needs a positive value (a tolerance zone,
//! a length's nominal size), positive *as written*: `fmt_num` keeps six decimals, so a
//! zone of 1e-7 mm would be written `0 mm`. What fails leaves its item out, with a
//! comment in the spec and a warning ([`super::errors::LeftOut`]).

use crate::model::fmt_num;

/// The largest size of a number written (mm or degrees).
pub(super) const LARGEST: f64 = 1e6;

/// What sign the spec needs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Sign {
    /// Above zero: a zone's width, a length's nominal size.
    Positive,
    /// Any finite value: a deviation, an angle.
    Any,
}

/// `x` as the spec writes it, and the value that text reads back as; `Err` with what is
/// wrong (``a zone of `inf mm` ``) when the spec cannot hold it. `what` names the value
/// (`a zone`), `unit` is written after it.
pub(super) fn written(x: f64, sign: Sign, what: &str, unit: &str) -> Result<(String, f64), String> {
    let shown = |text: String| format!("{what} of `{text} {unit}`");
    if !x.is_finite() {
        return Err(format!(
            "{}, which is not a finite number",
            shown(x.to_string())
        ));
    }
    if x.abs() > LARGEST {
        return Err(format!("{}, larger than any part", shown(format!("{x:e}"))));
    }
    let text = fmt_num(x);
    let back: f64 = text.parse().unwrap_or(f64::NAN);
    if sign == Sign::Positive && (back.is_nan() || back <= 0.0) {
        return Err(format!(
            "{}, which is not above 0",
            shown(if x == back { text } else { format!("{x:e}") })
        ));
    }
    Ok((text, back))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_what_the_spec_holds_is_written() {
        assert_eq!(
            written(0.05, Sign::Positive, "a zone", "mm").unwrap().0,
            "0.05"
        );
        assert_eq!(written(-0.1, Sign::Any, "a limit", "mm").unwrap().1, -0.1);
        for bad in [f64::INFINITY, f64::NAN, 0.0, -0.1, 1e-9, 1e300] {
            assert!(
                written(bad, Sign::Positive, "a zone", "mm").is_err(),
                "{bad}"
            );
        }
        assert!(written(f64::NEG_INFINITY, Sign::Any, "a limit", "mm").is_err());
    }
}
