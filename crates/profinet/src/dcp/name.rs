//! The name of station and its rules (IEC 61158-6-10, NameOfStation).
//!
//! A valid name is 1…240 bytes of one or more labels separated by `.`; each
//! label is 1…63 bytes of `a`–`z`, `0`–`9` and `-`, and neither starts nor ends
//! with `-`. The name must not have the form `n.n.n.n` (n = 0…999, it would read
//! as an IP address), and its first label must not be `port-xyz` or
//! `port-xyz-abcde` with digits x…e (those name ports in LLDP). Upper case is
//! refused, not folded: the controller's engineering tool writes lower case.
//! The empty name is "no name" ([`NameOfStation::EMPTY`]), which a Set may write
//! to clear the name.

use heapless::String;

/// Longest name of station, in bytes.
pub const MAX_LEN: usize = 240;
/// Longest label, in bytes.
pub const MAX_LABEL_LEN: usize = 63;

/// Why a name of station was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NameError {
    /// Longer than 240 bytes.
    TooLong,
    /// A label is empty (leading, trailing or double `.`) or longer than 63.
    LabelLength,
    /// A byte other than `a`–`z`, `0`–`9`, `-`, `.`.
    Character,
    /// A label starts or ends with `-`.
    Hyphen,
    /// The form `n.n.n.n` of an IP address.
    IpLike,
    /// The first label is `port-xyz` or `port-xyz-abcde`.
    PortLike,
}

/// A validated name of station (possibly empty: no name).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct NameOfStation(String<MAX_LEN>);

impl NameOfStation {
    /// No name.
    pub const EMPTY: NameOfStation = NameOfStation(String::new());

    /// Checks `bytes` against the rules; the empty slice gives
    /// [`NameOfStation::EMPTY`].
    pub fn new(bytes: &[u8]) -> Result<NameOfStation, NameError> {
        if bytes.is_empty() {
            return Ok(NameOfStation::EMPTY);
        }
        validate(bytes)?;
        let s = core::str::from_utf8(bytes).map_err(|_| NameError::Character)?;
        let mut out = String::new();
        out.push_str(s).map_err(|_| NameError::TooLong)?;
        Ok(NameOfStation(out))
    }

    /// The name.
    pub fn as_str(&self) -> &str {
        self.0.as_str()
    }

    /// The name's bytes.
    pub fn as_bytes(&self) -> &[u8] {
        self.0.as_bytes()
    }

    /// `true` if no name is set.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

impl core::str::FromStr for NameOfStation {
    type Err = NameError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        NameOfStation::new(s.as_bytes())
    }
}

/// Checks a non-empty name against the rules of the module doc.
pub fn validate(name: &[u8]) -> Result<(), NameError> {
    if name.len() > MAX_LEN {
        return Err(NameError::TooLong);
    }
    let mut labels = 0usize;
    let mut all_digit_labels = 0usize;
    for label in name.split(|&b| b == b'.') {
        labels += 1;
        if label.is_empty() || label.len() > MAX_LABEL_LEN {
            return Err(NameError::LabelLength);
        }
        if !label
            .iter()
            .all(|&b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'-')
        {
            return Err(NameError::Character);
        }
        if label.first() == Some(&b'-') || label.last() == Some(&b'-') {
            return Err(NameError::Hyphen);
        }
        if label.len() <= 3 && label.iter().all(u8::is_ascii_digit) {
            all_digit_labels += 1;
        }
    }
    if labels == 4 && all_digit_labels == 4 {
        return Err(NameError::IpLike);
    }
    let first = name.split(|&b| b == b'.').next().unwrap_or(&[]);
    if is_port_name(first) {
        return Err(NameError::PortLike);
    }
    Ok(())
}

/// `port-xyz` or `port-xyz-abcde` with digits (the LLDP port-ID form).
fn is_port_name(label: &[u8]) -> bool {
    let digits = |s: &[u8]| s.iter().all(u8::is_ascii_digit);
    match label.strip_prefix(b"port-") {
        Some(rest) => match rest.len() {
            3 => digits(rest),
            9 => match rest.split_at(3) {
                (xyz, [b'-', abcde @ ..]) => digits(xyz) && digits(abcde),
                _ => false,
            },
            _ => false,
        },
        None => false,
    }
}
