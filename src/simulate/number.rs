//! The one reading of a number the virtual CMM takes from outside: a statement's
//! parameter (coordinates, angles, a tolerance's zone and limits, a nominal's size, a
//! count) and a value of the deviations file.
//!
//! **Decision:** a number is what Rust's `f64` parser reads (DMIS 5.3, ANSI/DMIS 105.2
//! part 1, writes reals as decimals, with or without an exponent; a word such as `2D`
//! or `CART` is no number and is left to the statement), and it must be finite: `f64`
//! also reads `inf`, `NaN` and `1e999`, which no DMIS real spells. A `TOL/PERP,inf`
//! read as a zone wider than any part, or a `ROTATE` by NaN, would otherwise judge
//! every part good in silence. Size is the reader's business: a count of scanned
//! points runs to millions, an axis `(0, 1e300, 0)` is still a direction, and what a
//! value must be (a zone above 0) is checked where its meaning is known.

/// Why a text that reads as a number cannot be used.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct NotFinite;

impl NotFinite {
    /// What is wrong with `text`, as a diagnostic's message says it.
    pub(crate) fn what(self, text: &str) -> String {
        format!("`{text}`, which is not a finite number")
    }

    /// The remedy.
    pub(crate) fn help(self) -> String {
        "write a finite decimal number (no `inf`, `nan` or out-of-range exponent)".into()
    }
}

/// `text` as a number: `Ok(None)` for a word, `Err` for one that is not finite.
pub(crate) fn number(text: &str) -> Result<Option<f64>, NotFinite> {
    match text.parse::<f64>() {
        Err(_) => Ok(None),
        Ok(x) if x.is_finite() => Ok(Some(x)),
        Ok(_) => Err(NotFinite),
    }
}

/// `text` as a usable number, or nothing (a word or a number refused): for readers
/// after the statement's parameters were checked with [`number`].
pub(crate) fn value(text: &str) -> Option<f64> {
    number(text).ok().flatten()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_numbers_and_refusals() {
        assert_eq!(number("CART"), Ok(None));
        assert_eq!(number("2D"), Ok(None));
        assert_eq!(number("-0.25"), Ok(Some(-0.25)));
        assert_eq!(number("1.5E-3"), Ok(Some(1.5e-3)));
        assert_eq!(number("2652000"), Ok(Some(2_652_000.0)));
        for t in ["inf", "-inf", "NaN", "nan", "infinity", "1e999", "-1e400"] {
            assert_eq!(number(t), Err(NotFinite), "{t}");
            assert_eq!(value(t), None, "{t}");
        }
    }
}
