//! Numbers (spec 6.1.4.2): `["+"|"-"]` digits with an optional decimal point, then an optional exponent of
//! `E` or `e`, an optional sign and 1-3 digits; at most 16 digits before the exponent.

use std::fmt;
use std::str::FromStr;

use super::WireError;

/// The spec's limit on the digits of a number (the exponent's digits not counted: NIST's
/// `+1.234567890123456E003` is valid).
const MAX_DIGITS: usize = 16;

/// A number as written on the wire, with its value.
///
/// The text is kept as received so that a parsed line formats back to the same bytes (`+0090` stays
/// `+0090`); two numbers are equal when their texts are. Built from an `f64` with [`Number::from_f64`].
#[derive(Debug, Clone, PartialEq)]
pub struct Number {
    text: Box<str>,
    value: f64,
}

impl Number {
    /// The shortest text that reads back as `value`, written without an exponent when that fits in 16
    /// digits (`123.456`, `0.001`, `-90`), with one otherwise (`1.5E-20`). A value that needs 17
    /// significant digits is rounded to 16 (cut to 16 next to `f64::MAX`, where rounding up would pass
    /// it), a relative change below 1e-15, far under any CMM's resolution. NaN and infinities are
    /// refused; every number returned is one the wire parser reads back, finite.
    pub fn from_f64(value: f64) -> Result<Self, WireError> {
        if !value.is_finite() {
            return Err(WireError::NonFiniteNumber);
        }
        // Through the parser, so that a text it would refuse can never be sent.
        format_f64(value).parse()
    }

    /// The value (always finite).
    pub fn value(&self) -> f64 {
        self.value
    }

    /// The text as it goes on the wire.
    pub fn as_str(&self) -> &str {
        &self.text
    }

    /// Reads the number at the start of `input`; returns it and its length, or the problem and its offset.
    /// Stops at the first byte that cannot continue a number, which the caller must check.
    pub(crate) fn scan(input: &[u8]) -> Result<(Self, usize), (WireError, usize)> {
        let mut end = usize::from(matches!(input.first(), Some(b'+' | b'-')));
        let mut digits = 0;
        let mut seen_point = false;
        loop {
            match input.get(end) {
                Some(byte) if byte.is_ascii_digit() => digits += 1,
                Some(b'.') if !seen_point => seen_point = true,
                Some(b'.') => return Err((WireError::NumberTwoDecimalPoints, end)),
                _ => break,
            }
            end += 1;
        }
        if digits == 0 {
            return Err((WireError::NumberWithoutDigits, 0));
        }
        if digits > MAX_DIGITS {
            return Err((WireError::NumberTooManyDigits { digits }, 0));
        }
        if let Some(b'E' | b'e') = input.get(end) {
            let exponent_at = end;
            end += 1;
            if let Some(b'+' | b'-') = input.get(end) {
                end += 1;
            }
            let exponent_digits = input[end..]
                .iter()
                .take_while(|byte| byte.is_ascii_digit())
                .count();
            if !(1..=3).contains(&exponent_digits) {
                return Err((WireError::NumberBadExponent, exponent_at));
            }
            end += exponent_digits;
        }
        let text = std::str::from_utf8(&input[..end]).expect("scanned bytes are ASCII");
        // Rust's float syntax is a superset of the spec's, so every scanned text parses.
        let value: f64 = text
            .parse()
            .expect("a scanned number is a valid f64 literal");
        if !value.is_finite() {
            return Err((WireError::NumberOutOfRange, 0));
        }
        Ok((
            Number {
                text: text.into(),
                value,
            },
            end,
        ))
    }
}

impl FromStr for Number {
    type Err = WireError;

    /// Reads a number that is the whole of `text`.
    fn from_str(text: &str) -> Result<Self, WireError> {
        let (number, len) = Number::scan(text.as_bytes()).map_err(|(problem, _)| problem)?;
        match text.as_bytes().get(len) {
            None => Ok(number),
            Some(&byte) => Err(WireError::Expected {
                expected: "end of number",
                found: Some(byte),
            }),
        }
    }
}

impl fmt::Display for Number {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.text)
    }
}

/// Writes a finite value as described on [`Number::from_f64`].
fn format_f64(value: f64) -> String {
    if value == 0.0 {
        return "0".to_owned();
    }
    // `{:e}` gives the shortest digits that read back as `value`; past 16 of them, round to 16.
    let mut scientific = format!("{value:e}");
    let shortest_digits = significant_digits(&scientific);
    if shortest_digits > MAX_DIGITS {
        let rounded = format!("{:.*e}", MAX_DIGITS - 1, value);
        scientific = if rounded.parse::<f64>().is_ok_and(f64::is_finite) {
            rounded
        } else {
            // Within half a 16-digit step of f64::MAX, rounding up gives 1.797693134862316E308, which
            // reads back as infinity; the digits cut to 16 are the nearest finite text.
            let (mantissa, exponent) = scientific
                .split_once('e')
                .expect("`{:e}` writes an exponent");
            let cut = mantissa.len() - (shortest_digits - MAX_DIGITS);
            format!("{}e{exponent}", &mantissa[..cut])
        };
    }
    let (mantissa, exponent) = scientific
        .split_once('e')
        .expect("`{:e}` writes an exponent");
    let exponent: i32 = exponent.parse().expect("`{:e}` writes an integer exponent");
    let (sign, mantissa) = mantissa
        .strip_prefix('-')
        .map_or(("", mantissa), |rest| ("-", rest));
    let digits: String = mantissa.chars().filter(char::is_ascii_digit).collect();
    let digits = digits.trim_end_matches('0');
    let count = i32::try_from(digits.len()).expect("at most 17 digits");

    if (0..MAX_DIGITS as i32).contains(&exponent) {
        // Integer part of exponent + 1 digits; pad with zeros or place the point inside the digits.
        let integer_len = exponent + 1;
        if count <= integer_len {
            return format!(
                "{sign}{digits}{}",
                "0".repeat((integer_len - count) as usize)
            );
        }
        let (integer, fraction) = digits.split_at(integer_len as usize);
        return format!("{sign}{integer}.{fraction}");
    }
    // `0.` then -exponent - 1 zeros then the digits: 1 - exponent - 1 + count digits in all.
    if exponent < 0 && count - exponent <= MAX_DIGITS as i32 {
        return format!("{sign}0.{}{digits}", "0".repeat((-exponent - 1) as usize));
    }
    let (first, rest) = digits.split_at(1);
    let point = if rest.is_empty() { "" } else { "." };
    format!("{sign}{first}{point}{rest}E{exponent}")
}

/// Digits of the mantissa of a `{:e}`-formatted float.
fn significant_digits(scientific: &str) -> usize {
    scientific
        .split('e')
        .next()
        .unwrap_or_default()
        .chars()
        .filter(char::is_ascii_digit)
        .count()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn text_of(value: f64) -> String {
        Number::from_f64(value).unwrap().to_string()
    }

    #[test]
    fn formats_cmm_values_without_exponent() {
        assert_eq!(text_of(0.0), "0");
        assert_eq!(text_of(-0.0), "0");
        assert_eq!(text_of(100.0), "100");
        assert_eq!(text_of(-90.0), "-90");
        assert_eq!(text_of(123.456), "123.456");
        assert_eq!(text_of(0.001), "0.001");
        assert_eq!(text_of(-1.2), "-1.2");
        assert_eq!(text_of(1e-7), "0.0000001");
        assert_eq!(text_of(1234567890123456.0), "1234567890123456");
    }

    #[test]
    fn uses_exponent_only_past_16_digits() {
        assert_eq!(text_of(1e16), "1E16");
        assert_eq!(text_of(-2.5e300), "-2.5E300");
        assert_eq!(text_of(1.5e-20), "1.5E-20");
        assert_eq!(text_of(1.234e-15), "1.234E-15");
        assert_eq!(text_of(f64::MIN_POSITIVE), "2.225073858507201E-308");
    }

    #[test]
    fn rounds_seventeen_digit_values_to_sixteen() {
        let sum = 0.1 + 0.2; // shortest form 0.30000000000000004, 17 digits
        let number = Number::from_f64(sum).unwrap();
        assert_eq!(number.as_str(), "0.3");
        assert!((number.value() - sum).abs() <= sum * 1e-15);
    }

    #[test]
    fn the_extremes_read_back_finite() {
        let largest_subnormal = f64::from_bits(f64::MIN_POSITIVE.to_bits() - 1);
        let below_max = f64::from_bits(f64::MAX.to_bits() - 1);
        for (value, text) in [
            (f64::MAX, "1.797693134862315E308"),
            (-f64::MAX, "-1.797693134862315E308"),
            (below_max, "1.797693134862315E308"),
            (f64::MIN_POSITIVE, "2.225073858507201E-308"),
            (-f64::MIN_POSITIVE, "-2.225073858507201E-308"),
            (largest_subnormal, "2.225073858507201E-308"),
            (5e-324, "5E-324"),
            (-5e-324, "-5E-324"),
            (1e-310, "1E-310"),
        ] {
            let number = Number::from_f64(value).unwrap_or_else(|e| panic!("{value:e}: {e}"));
            assert_eq!(number.as_str(), text, "{value:e}");
            let read: Number = number.as_str().parse().unwrap();
            assert!(read.value().is_finite(), "{value:e}");
            assert_eq!(read.value(), number.value(), "{value:e}");
            assert!(
                (number.value() - value).abs() <= value.abs() * 1e-15,
                "{value:e} read back as {:e}",
                number.value()
            );
        }
        // MIN_POSITIVE's 16-digit text is nearer the largest subnormal: the nearest value to the text.
        assert_eq!(
            Number::from_f64(f64::MIN_POSITIVE).unwrap().value(),
            largest_subnormal
        );
    }

    proptest! {
        #[test]
        fn every_finite_value_reads_back_through_the_parser(
            // Any bits, and more often the ends of the range: the values next to f64::MAX and the subnormals.
            magnitude in prop_oneof![
                any::<u64>(),
                (f64::MAX.to_bits() - 16)..=f64::MAX.to_bits(),
                0..f64::MIN_POSITIVE.to_bits() + 4096,
            ],
            negative in any::<bool>(),
        ) {
            let value = f64::from_bits(magnitude).copysign(if negative { -1.0 } else { 1.0 });
            prop_assume!(value.is_finite());
            let number = Number::from_f64(value).unwrap();
            let read: Number = number.as_str().parse().unwrap();
            prop_assert!(read.value().is_finite());
            prop_assert_eq!(read.value(), number.value());
            if significant_digits(&format!("{value:e}")) <= MAX_DIGITS {
                prop_assert_eq!(number.value(), value);
            } else {
                prop_assert!((number.value() - value).abs() <= value.abs() * 1e-15);
            }
        }
    }

    #[test]
    fn refuses_non_finite_values() {
        assert_eq!(Number::from_f64(f64::NAN), Err(WireError::NonFiniteNumber));
        assert!(Number::from_f64(f64::INFINITY).is_err());
    }

    #[test]
    fn reads_every_form_nist_lists_as_valid() {
        // numbersCmdOK.txt / numbersResOK.txt: signs, leading zeros, points at either end, E and e exponents.
        for text in [
            "0",
            "123",
            "+90",
            "-90",
            "12.2",
            "+1.2",
            "-1.2",
            "1234567890123456",
            "1.234567890123456",
            "+1.234567890123456",
            "-0000",
            "0090",
            "+0090",
            "-0090",
            "+0000.5",
            "+0000.5E7",
            "3.9E2",
            "1.3E02",
            "3.8E002",
            "-6.382E-012",
            "+1.234567890123456e-123",
            "+6.333e+01",
            ".123",
            "123.",
        ] {
            let number: Number = text.parse().unwrap_or_else(|e| panic!("{text}: {e}"));
            assert_eq!(number.as_str(), text);
            assert_eq!(number.value(), text.parse::<f64>().unwrap());
        }
    }

    #[test]
    fn rejects_every_form_nist_lists_as_invalid() {
        // numbersErrorCmd.txt: more than 16 digits, no digits, two points, exponent of 0 or 4 digits.
        assert_eq!(
            "12345678901234567".parse::<Number>(),
            Err(WireError::NumberTooManyDigits { digits: 17 })
        );
        assert_eq!("-.".parse::<Number>(), Err(WireError::NumberWithoutDigits));
        assert_eq!("+".parse::<Number>(), Err(WireError::NumberWithoutDigits));
        assert_eq!("+1.2E".parse::<Number>(), Err(WireError::NumberBadExponent));
        assert_eq!(
            "+1.2E0010".parse::<Number>(),
            Err(WireError::NumberBadExponent)
        );
        assert_eq!(
            "0.34.33".parse::<Number>(),
            Err(WireError::NumberTwoDecimalPoints)
        );
        assert!(matches!(
            "+1.2 E2".parse::<Number>(),
            Err(WireError::Expected {
                found: Some(b' '),
                ..
            })
        ));
        assert_eq!("1E999".parse::<Number>(), Err(WireError::NumberOutOfRange));
    }

    #[test]
    fn scan_stops_at_the_end_of_the_number() {
        let (number, len) = Number::scan(b"-1.5e3), Y(2)").unwrap();
        assert_eq!(
            (number.as_str(), number.value(), len),
            ("-1.5e3", -1500.0, 6)
        );
    }
}
