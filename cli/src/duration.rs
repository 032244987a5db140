//! Parsing and checking of `--duration` values.

/// Parses a duration in seconds: `2`, `2.5`, `2.5s` or `250ms`. Rejects
/// zero, negative, non-finite and non-numeric values (clap reports the
/// message and exits with code 2).
pub fn parse_duration(text: &str) -> Result<f64, String> {
    let t = text.trim();
    let (number, scale) = if let Some(n) = t.strip_suffix("ms") {
        (n, 1e-3)
    } else if let Some(n) = t.strip_suffix('s') {
        (n, 1.0)
    } else {
        (t, 1.0)
    };
    let value: f64 = number.trim().parse().map_err(|_| {
        format!("`{text}` is not a duration; expected seconds, e.g. 2.5, 2.5s or 250ms")
    })?;
    let secs = value * scale;
    if !secs.is_finite() {
        return Err(format!("duration `{text}` must be finite"));
    }
    if secs <= 0.0 {
        return Err(format!("duration `{text}` must be greater than zero"));
    }
    Ok(secs)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accepts_units() {
        assert_eq!(parse_duration("2").unwrap(), 2.0);
        assert_eq!(parse_duration("2.5s").unwrap(), 2.5);
        assert!((parse_duration("250ms").unwrap() - 0.25).abs() < 1e-15);
    }

    #[test]
    fn rejects_bad_values() {
        for bad in ["", "abc", "-1", "0", "0ms", "nan", "inf", "1h"] {
            assert!(parse_duration(bad).is_err(), "{bad} accepted");
        }
    }
}
