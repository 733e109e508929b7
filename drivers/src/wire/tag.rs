//! Tags: columns 1-5 of every line (spec 6.2.1).

use std::fmt;

use super::WireError;

/// A normal-queue tag, 00001-99999.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct CommandTag(u32);

/// A fast-queue (event) tag, E0001-E9999. Also the argument of `StopDaemon(E0553)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct EventTag(u16);

/// The tag of a line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Tag {
    /// 00001-99999: a normal-queue transaction.
    Command(CommandTag),
    /// E0001-E9999: a fast-queue transaction (commands whose name ends in `E`) and its events.
    Event(EventTag),
    /// E0000: something the server reports unprompted, such as an emergency stop.
    Unsolicited,
}

impl CommandTag {
    /// The tag with this number, if it is in 1-99999.
    pub fn new(number: u32) -> Result<Self, WireError> {
        if (1..=99_999).contains(&number) {
            Ok(CommandTag(number))
        } else {
            Err(WireError::TagOutOfRange {
                number,
                range: "00001-99999",
            })
        }
    }

    /// The tag's number.
    pub fn number(self) -> u32 {
        self.0
    }
}

impl EventTag {
    /// The tag E`number`, if `number` is in 1-9999 (E0000 is [`Tag::Unsolicited`], not an event tag).
    pub fn new(number: u16) -> Result<Self, WireError> {
        if (1..=9_999).contains(&number) {
            Ok(EventTag(number))
        } else {
            Err(WireError::TagOutOfRange {
                number: number.into(),
                range: "E0001-E9999",
            })
        }
    }

    /// The tag's number.
    pub fn number(self) -> u16 {
        self.0
    }

    /// Reads `E` and four digits; `None` if `text` is anything else (E0000 included).
    pub(crate) fn from_text(text: &[u8]) -> Option<Self> {
        match text {
            [b'E', digits @ ..] => EventTag::new(four_digits(digits)?).ok(),
            _ => None,
        }
    }
}

impl Tag {
    /// Reads columns 1-5 of a line.
    pub(crate) fn parse(line: &[u8]) -> Result<Self, WireError> {
        let text = line.get(..5).ok_or(WireError::BadTag)?;
        match text {
            [b'E', digits @ ..] => match four_digits(digits).ok_or(WireError::BadTag)? {
                0 => Ok(Tag::Unsolicited),
                number => EventTag::new(number).map(Tag::Event),
            },
            [first, digits @ ..] if first.is_ascii_digit() => {
                let low = u32::from(four_digits(digits).ok_or(WireError::BadTag)?);
                CommandTag::new(u32::from(first - b'0') * 10_000 + low).map(Tag::Command)
            }
            _ => Err(WireError::BadTag),
        }
    }
}

/// The value of exactly four ASCII digits.
fn four_digits(text: &[u8]) -> Option<u16> {
    if text.len() != 4 || !text.iter().all(u8::is_ascii_digit) {
        return None;
    }
    Some(
        text.iter()
            .fold(0, |value, digit| value * 10 + u16::from(digit - b'0')),
    )
}

impl fmt::Display for CommandTag {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:05}", self.0)
    }
}

impl fmt::Display for EventTag {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "E{:04}", self.0)
    }
}

impl fmt::Display for Tag {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Tag::Command(tag) => tag.fmt(f),
            Tag::Event(tag) => tag.fmt(f),
            Tag::Unsolicited => f.write_str("E0000"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_with_leading_zeros() {
        assert_eq!(
            Tag::Command(CommandTag::new(1).unwrap()).to_string(),
            "00001"
        );
        assert_eq!(
            Tag::Command(CommandTag::new(99_999).unwrap()).to_string(),
            "99999"
        );
        assert_eq!(Tag::Event(EventTag::new(553).unwrap()).to_string(), "E0553");
        assert_eq!(Tag::Unsolicited.to_string(), "E0000");
    }

    #[test]
    fn parses_the_three_kinds() {
        assert_eq!(
            Tag::parse(b"04711 Home()"),
            Ok(Tag::Command(CommandTag(4711)))
        );
        assert_eq!(Tag::parse(b"E3333"), Ok(Tag::Event(EventTag(3333))));
        assert_eq!(Tag::parse(b"E0000 ! Error"), Ok(Tag::Unsolicited));
    }

    #[test]
    fn rejects_the_spec_examples_of_bad_tags() {
        // Spec 6.2.1: "20" (only 2 digits), "00000" (out of range), "E20", "A4711".
        assert_eq!(Tag::parse(b"20 Home()"), Err(WireError::BadTag));
        assert_eq!(
            Tag::parse(b"00000"),
            Err(WireError::TagOutOfRange {
                number: 0,
                range: "00001-99999"
            })
        );
        assert_eq!(Tag::parse(b"E20 H"), Err(WireError::BadTag));
        assert_eq!(Tag::parse(b"A4711"), Err(WireError::BadTag));
        assert_eq!(Tag::parse(b"0 001"), Err(WireError::BadTag));
        assert_eq!(Tag::parse(b"E+001"), Err(WireError::BadTag));
        assert_eq!(Tag::parse(b"0001"), Err(WireError::BadTag));
    }

    #[test]
    fn constructors_check_ranges() {
        assert!(CommandTag::new(0).is_err());
        assert!(CommandTag::new(100_000).is_err());
        assert!(EventTag::new(0).is_err());
        assert!(EventTag::new(10_000).is_err());
        assert_eq!(EventTag::from_text(b"E0553"), Some(EventTag(553)));
        assert_eq!(EventTag::from_text(b"E0000"), None);
        assert_eq!(EventTag::from_text(b"E055"), None);
    }
}
