//! ISO 286 fits as size limits: a dimension the file tolerances as `Ø25 G6` or `Ø40 p6`
//! gets the deviations ISO 286 gives that designation, so that the spec checks the
//! size against them as the drawing means.
//!
//! The values are ISO 286-1:2010's standard tolerance grades (Table 1, IT4–IT14) and
//! ISO 286-2:2010's fundamental deviations for the letters fits use (holes D E F G H JS
//! K M N P, shafts d e f g h js k m n p), for nominal sizes up to 500 mm, in
//! micrometres; a hole's deviation mirrors its shaft's (EI = −es), and K, M, N up to
//! IT8 and P up to IT7 add Δ = ITn − ITn−1 (ISO 286-1 § 5.3.2.4; Δ is 0 up to 3 mm).
//! Other letters, grades and sizes are refused with the reason, never guessed.

/// Upper bounds of ISO 286's nominal size ranges (mm): "over 3 up to and including 6".
const RANGES: [f64; 13] = [
    3.0, 6.0, 10.0, 18.0, 30.0, 50.0, 80.0, 120.0, 180.0, 250.0, 315.0, 400.0, 500.0,
];

/// Standard tolerance grades IT4–IT14 per range (µm), ISO 286-1 Table 1.
const IT: [[f64; 13]; 11] = [
    [
        3.0, 4.0, 4.0, 5.0, 6.0, 7.0, 8.0, 10.0, 12.0, 14.0, 16.0, 18.0, 20.0,
    ],
    [
        4.0, 5.0, 6.0, 8.0, 9.0, 11.0, 13.0, 15.0, 18.0, 20.0, 23.0, 25.0, 27.0,
    ],
    [
        6.0, 8.0, 9.0, 11.0, 13.0, 16.0, 19.0, 22.0, 25.0, 29.0, 32.0, 36.0, 40.0,
    ],
    [
        10.0, 12.0, 15.0, 18.0, 21.0, 25.0, 30.0, 35.0, 40.0, 46.0, 52.0, 57.0, 63.0,
    ],
    [
        14.0, 18.0, 22.0, 27.0, 33.0, 39.0, 46.0, 54.0, 63.0, 72.0, 81.0, 89.0, 97.0,
    ],
    [
        25.0, 30.0, 36.0, 43.0, 52.0, 62.0, 74.0, 87.0, 100.0, 115.0, 130.0, 140.0, 155.0,
    ],
    [
        40.0, 48.0, 58.0, 70.0, 84.0, 100.0, 120.0, 140.0, 160.0, 185.0, 210.0, 230.0, 250.0,
    ],
    [
        60.0, 75.0, 90.0, 110.0, 130.0, 160.0, 190.0, 220.0, 250.0, 290.0, 320.0, 360.0, 400.0,
    ],
    [
        100.0, 120.0, 150.0, 180.0, 210.0, 250.0, 300.0, 350.0, 400.0, 460.0, 520.0, 570.0, 630.0,
    ],
    [
        140.0, 180.0, 220.0, 270.0, 330.0, 390.0, 460.0, 540.0, 630.0, 720.0, 810.0, 890.0, 970.0,
    ],
    [
        250.0, 300.0, 360.0, 430.0, 520.0, 620.0, 740.0, 870.0, 1000.0, 1150.0, 1300.0, 1400.0,
        1550.0,
    ],
];

/// Shafts' fundamental deviations per range (µm), ISO 286-2: the upper deviation es of
/// d–h, the lower deviation ei of k (for IT4–IT7; 0 for other grades), m, n, p.
const SHAFT: [(char, [f64; 13]); 9] = [
    (
        'd',
        [
            -20.0, -30.0, -40.0, -50.0, -65.0, -80.0, -100.0, -120.0, -145.0, -170.0, -190.0,
            -210.0, -230.0,
        ],
    ),
    (
        'e',
        [
            -14.0, -20.0, -25.0, -32.0, -40.0, -50.0, -60.0, -72.0, -85.0, -100.0, -110.0, -125.0,
            -135.0,
        ],
    ),
    (
        'f',
        [
            -6.0, -10.0, -13.0, -16.0, -20.0, -25.0, -30.0, -36.0, -43.0, -50.0, -56.0, -62.0,
            -68.0,
        ],
    ),
    (
        'g',
        [
            -2.0, -4.0, -5.0, -6.0, -7.0, -9.0, -10.0, -12.0, -14.0, -15.0, -17.0, -18.0, -20.0,
        ],
    ),
    ('h', [0.0; 13]),
    (
        'k',
        [
            0.0, 1.0, 1.0, 1.0, 2.0, 2.0, 2.0, 3.0, 3.0, 4.0, 4.0, 4.0, 5.0,
        ],
    ),
    (
        'm',
        [
            2.0, 4.0, 6.0, 7.0, 8.0, 9.0, 11.0, 13.0, 15.0, 17.0, 20.0, 21.0, 23.0,
        ],
    ),
    (
        'n',
        [
            4.0, 8.0, 10.0, 12.0, 15.0, 17.0, 20.0, 23.0, 27.0, 31.0, 34.0, 37.0, 40.0,
        ],
    ),
    (
        'p',
        [
            6.0, 12.0, 15.0, 18.0, 22.0, 26.0, 32.0, 37.0, 43.0, 50.0, 56.0, 62.0, 68.0,
        ],
    ),
];

/// The (upper, lower) deviations in mm ISO 286 gives the fit `fit` (`H7`, `g6`, `JS7`)
/// at the nominal size `nominal` (mm); Err with why it cannot.
pub(crate) fn deviations(fit: &str, nominal: f64) -> Result<(f64, f64), String> {
    let fit = fit.trim();
    let split = fit
        .find(|c: char| c.is_ascii_digit())
        .ok_or_else(|| format!("`{fit}` names no tolerance grade"))?;
    let (letters, grade) = fit.split_at(split);
    let grade: usize = grade
        .parse()
        .map_err(|_| format!("`{fit}`'s grade is not a whole number"))?;
    if !(4..=14).contains(&grade) {
        return Err(format!(
            "IT{grade} is outside the grades inspc tables (IT4–IT14)"
        ));
    }
    let range = RANGES
        .iter()
        .position(|&top| nominal <= top)
        .filter(|_| nominal > 0.0)
        .ok_or_else(|| {
            format!("{nominal} mm is outside ISO 286's sizes inspc tables (up to 500 mm)")
        })?;
    let it = |g: usize| IT[g - 4][range];
    let t = it(grade);
    let hole = letters
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_uppercase());
    let letter = letters.to_ascii_lowercase();
    let shaft_fd = |c: char| {
        SHAFT
            .iter()
            .find(|(l, _)| *l == c)
            .map(|(_, v)| v[range])
            .ok_or_else(|| format!("the fit letter `{letters}` is not one inspc tables"))
    };
    let (upper, lower) = match (letter.as_str(), hole) {
        ("js", _) => (t / 2.0, -t / 2.0),
        (l @ ("d" | "e" | "f" | "g" | "h"), false) => {
            let es = shaft_fd(first(l))?;
            (es, es - t)
        }
        (l @ ("d" | "e" | "f" | "g" | "h"), true) => {
            let ei = -shaft_fd(first(l))?;
            (ei + t, ei)
        }
        (l @ ("k" | "m" | "n" | "p"), false) => {
            let mut ei = shaft_fd(first(l))?;
            if l == "k" && !(4..=7).contains(&grade) {
                ei = 0.0;
            }
            (ei + t, ei)
        }
        (l @ ("k" | "m" | "n" | "p"), true) => {
            let ei = shaft_fd(first(l))?;
            let delta_rule = if l == "p" { grade <= 7 } else { grade <= 8 };
            if grade == 4 && range > 0 {
                return Err(format!("`{fit}` needs IT3's Δ, which inspc does not table"));
            }
            let delta = if range == 0 { 0.0 } else { t - it(grade - 1) };
            let es = match l {
                // ISO 286-2 Table 3's special cases: M6 over 250 up to 315 mm.
                "m" if grade == 6 && range == 10 => -9.0,
                _ if delta_rule => -ei + delta,
                // N above IT8: 0, but −4 µm up to 3 mm.
                "n" if range == 0 => -4.0,
                "k" | "n" => 0.0,
                _ => -ei,
            };
            (es, es - t)
        }
        _ => {
            return Err(format!(
                "the fit letter `{letters}` is not one inspc tables"
            ))
        }
    };
    Ok((upper / 1000.0, lower / 1000.0))
}

fn first(l: &str) -> char {
    l.chars().next().unwrap_or(' ')
}

#[cfg(test)]
mod tests {
    use super::deviations;

    /// Published ISO 286-2 limits (µm) for common fits.
    #[test]
    fn common_fits_match_iso_286() {
        let cases: &[(&str, f64, f64, f64)] = &[
            ("H7", 25.0, 21.0, 0.0),
            ("g6", 25.0, -7.0, -20.0),
            ("G6", 25.0, 20.0, 7.0),
            ("f7", 40.0, -25.0, -50.0),
            ("k6", 25.0, 15.0, 2.0),
            ("p6", 40.0, 42.0, 26.0),
            ("N7", 25.0, -7.0, -28.0),
            ("K7", 25.0, 6.0, -15.0),
            ("M7", 25.0, 0.0, -21.0),
            ("P7", 25.0, -14.0, -35.0),
            ("K8", 25.0, 10.0, -23.0),
            ("JS7", 10.0, 7.5, -7.5),
            ("h9", 100.0, 0.0, -87.0),
            ("E9", 20.0, 92.0, 40.0),
            ("D10", 50.0, 180.0, 80.0),
            ("H11", 3.0, 60.0, 0.0),
            ("K7", 2.0, 0.0, -10.0),
            ("N9", 2.0, -4.0, -29.0),
            ("M6", 300.0, -9.0, -41.0),
        ];
        for &(fit, size, up, low) in cases {
            let (u, l) = deviations(fit, size).unwrap();
            assert!(
                (u * 1000.0 - up).abs() < 1e-9 && (l * 1000.0 - low).abs() < 1e-9,
                "{fit} at {size} mm: {u} / {l}"
            );
        }
    }

    #[test]
    fn what_is_not_tabled_is_refused() {
        assert!(deviations("H7", 600.0).is_err());
        assert!(deviations("zc8", 20.0).is_err());
        assert!(deviations("H2", 20.0).is_err());
        assert!(deviations("H", 20.0).is_err());
    }
}
