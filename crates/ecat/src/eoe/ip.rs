//! The set- and get-IP-parameter services (E-096, E-097): the request
//! layouts masters send, the checks, the response body.

use super::DNS_NAME_LEN;

/// Flags of the set/get-IP-parameter body (first 4 bytes after the header).
pub mod ip_flags {
    /// MAC address included.
    pub const MAC: u32 = 1 << 0;
    /// IP address included.
    pub const IP: u32 = 1 << 1;
    /// Subnet mask included.
    pub const MASK: u32 = 1 << 2;
    /// Default gateway included.
    pub const GATEWAY: u32 = 1 << 3;
    /// DNS server included.
    pub const DNS: u32 = 1 << 4;
    /// DNS name included.
    pub const DNS_NAME: u32 = 1 << 5;
}

/// The fields of the set/get-IP-parameter body after the 4-byte flags,
/// in order: flag and length. The DNS name is the last one.
const FIELDS: [(u32, usize); 6] = [
    (ip_flags::MAC, 6),
    (ip_flags::IP, 4),
    (ip_flags::MASK, 4),
    (ip_flags::GATEWAY, 4),
    (ip_flags::DNS, 4),
    (ip_flags::DNS_NAME, DNS_NAME_LEN),
];

/// Length of the flags that open the body.
const FLAGS_LEN: usize = 4;
/// Length of a body with every field.
pub const IP_BODY_LEN: usize = FLAGS_LEN + 6 + 4 * 4 + DNS_NAME_LEN;

/// How a master lays out the set-IP-parameter body (docs/conformance.md,
/// "EoE set-IP-parameter layout").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IpLayout {
    /// Only the flagged fields, one after the other (SOEM, SOES).
    Packed,
    /// Every field at its ETG.1000.6 position, an unflagged one still
    /// there (TwinCAT, the IgH master); the body may end after the last
    /// flagged field.
    Fixed,
}

/// Where each field starts in `layout` for `flags` (after the header).
fn offsets(flags: u32, layout: IpLayout) -> [usize; 6] {
    let mut at = [0; 6];
    let mut off = FLAGS_LEN;
    for (slot, &(flag, len)) in at.iter_mut().zip(FIELDS.iter()) {
        *slot = off;
        if layout == IpLayout::Fixed || flags & flag != 0 {
            off += len;
        }
    }
    at
}

/// Bytes a body of `layout` needs for `flags`: up to the end of the last
/// flagged field, of the DNS name at least one byte.
fn needed(flags: u32, layout: IpLayout) -> usize {
    let at = offsets(flags, layout);
    FIELDS
        .iter()
        .zip(at)
        .filter(|((flag, _), _)| flags & flag != 0)
        .map(|(&(flag, len), off)| off + if flag == ip_flags::DNS_NAME { 1 } else { len })
        .max()
        .unwrap_or(FLAGS_LEN)
}

/// The layout of a body of `len` bytes with `flags`: packed when it is
/// exactly as long as its flagged fields, else fixed when it reaches the
/// last flagged field's fixed position, else packed (a short DNS name).
/// Where the flagged fields have no gap both layouts are the same.
pub fn ip_layout(flags: u32, len: usize) -> IpLayout {
    let packed: usize = FLAGS_LEN
        + FIELDS
            .iter()
            .filter(|(flag, _)| flags & flag != 0)
            .map(|(_, len)| len)
            .sum::<usize>();
    if len != packed && len >= needed(flags, IpLayout::Fixed) {
        IpLayout::Fixed
    } else {
        IpLayout::Packed
    }
}

/// An IPv4 address from the wire: a little-endian UINT32, the first octet
/// last (`02 00 4d 0a` = 10.77.0.2), as SOEM, SOES and TwinCAT write it.
fn ip_from_wire(b: [u8; 4]) -> Ipv4 {
    [b[3], b[2], b[1], b[0]]
}

/// An IPv4 address for the wire (see [`ip_from_wire`]).
fn ip_to_wire(a: Ipv4) -> [u8; 4] {
    [a[3], a[2], a[1], a[0]]
}

/// An IPv4 address, first octet first (10.77.0.2 = `[10, 77, 0, 2]`).
pub type Ipv4 = [u8; 4];

/// The DNS name of the set-IP-parameter request (up to 32 bytes, NUL padded).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct DnsName {
    bytes: [u8; DNS_NAME_LEN],
    len: u8,
}

impl DnsName {
    /// From the request's field (cut at the first NUL).
    pub fn from_field(field: &[u8]) -> Self {
        let mut bytes = [0; DNS_NAME_LEN];
        let mut len = 0;
        for (dst, &b) in bytes.iter_mut().zip(field.iter().take_while(|&&b| b != 0)) {
            *dst = b;
            len += 1;
        }
        Self { bytes, len }
    }

    /// The name's bytes.
    pub fn as_bytes(&self) -> &[u8] {
        self.bytes.get(..usize::from(self.len)).unwrap_or_default()
    }
}

/// The IP parameters the master handed over (E-096); `None` = never set.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct IpParams {
    /// Virtual MAC address of the EoE interface.
    pub mac: Option<[u8; 6]>,
    /// IP address.
    pub ip: Option<Ipv4>,
    /// Subnet mask.
    pub mask: Option<Ipv4>,
    /// Default gateway.
    pub gateway: Option<Ipv4>,
    /// DNS server.
    pub dns: Option<Ipv4>,
    /// DNS name.
    pub dns_name: Option<DnsName>,
}

/// Why a set-IP-parameter request is refused (result
/// [`result::UNSPECIFIED_ERROR`](super::result::UNSPECIFIED_ERROR), EMCY FFF0h/23h).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum IpError {
    /// The request is shorter than its included fields.
    TooShort,
    /// Subnet mask not contiguous, or without room for two hosts (/31, /32).
    BadMask,
    /// IP address is the first (network) or last (broadcast) address of its
    /// subnet, 0.0.0.0 / 255.255.255.255, or multicast (E-097).
    HostAddress,
    /// Default gateway outside the subnet or not a host address.
    Gateway,
    /// MAC address is multicast or all zero.
    Mac,
}

/// Prefix length of a contiguous mask, `None` otherwise.
pub fn prefix_len(mask: Ipv4) -> Option<u32> {
    let m = u32::from_be_bytes(mask);
    let ones = m.leading_ones();
    (m.checked_shl(ones).unwrap_or(0) == 0).then_some(ones)
}

/// E-097 / C-150: `ip` is a usable host of the subnet `mask` (not its first
/// or last address). Masks of /31 and /32 have no such host.
pub fn is_host(ip: Ipv4, mask: Ipv4) -> bool {
    let (a, m) = (u32::from_be_bytes(ip), u32::from_be_bytes(mask));
    match prefix_len(mask) {
        Some(p) if p <= 30 => {
            let host = a & !m;
            host != 0 && host != !m
        }
        _ => false,
    }
}

/// Parses a set-IP-parameter request body (the EoE data after the header)
/// into the included fields, in either layout ([`ip_layout`]).
pub fn parse_set_ip(data: &[u8]) -> Result<IpParams, IpError> {
    let flags_bytes: [u8; 4] = data
        .get(..FLAGS_LEN)
        .and_then(|f| f.try_into().ok())
        .ok_or(IpError::TooShort)?;
    let flags = u32::from_le_bytes(flags_bytes);
    let layout = ip_layout(flags, data.len());
    if data.len() < needed(flags, layout) {
        return Err(IpError::TooShort);
    }
    let [mac, ip, mask, gateway, dns, name] = offsets(flags, layout);
    let ip4 = |flag: u32, off: usize| -> Option<Ipv4> {
        let b: [u8; 4] = data.get(off..off + 4)?.try_into().ok()?;
        (flags & flag != 0).then(|| ip_from_wire(b))
    };
    Ok(IpParams {
        mac: data
            .get(mac..mac + 6)
            .and_then(|m| m.try_into().ok())
            .filter(|_| flags & ip_flags::MAC != 0),
        ip: ip4(ip_flags::IP, ip),
        mask: ip4(ip_flags::MASK, mask),
        gateway: ip4(ip_flags::GATEWAY, gateway),
        dns: ip4(ip_flags::DNS, dns),
        // up to 32 bytes; a shorter (but non-empty) name field is accepted
        dns_name: data
            .get(name..)
            .filter(|_| flags & ip_flags::DNS_NAME != 0)
            .map(DnsName::from_field),
    })
}

/// The get-IP-parameter response body: the flags of the parameters set,
/// then those parameters packed in order (the layout SOEM reads; with every
/// parameter set it is also the fixed layout). Returns the body and its
/// length.
pub fn get_ip_body(p: &IpParams) -> ([u8; IP_BODY_LEN], usize) {
    let mut b = [0u8; IP_BODY_LEN];
    let mut flags = 0u32;
    let mut len = FLAGS_LEN;
    let mut put = |flag: u32, src: &[u8]| {
        if let Some(dst) = b.get_mut(len..len + src.len()) {
            dst.copy_from_slice(src);
            flags |= flag;
            len += src.len();
        }
    };
    if let Some(mac) = &p.mac {
        put(ip_flags::MAC, mac);
    }
    for (flag, v) in [
        (ip_flags::IP, p.ip),
        (ip_flags::MASK, p.mask),
        (ip_flags::GATEWAY, p.gateway),
        (ip_flags::DNS, p.dns),
    ] {
        if let Some(v) = v {
            put(flag, &ip_to_wire(v));
        }
    }
    if let Some(name) = &p.dns_name {
        let mut field = [0u8; DNS_NAME_LEN];
        for (d, s) in field.iter_mut().zip(name.as_bytes()) {
            *d = *s;
        }
        put(ip_flags::DNS_NAME, &field);
    }
    for (d, s) in b.iter_mut().zip(flags.to_le_bytes()) {
        *d = s;
    }
    (b, len)
}

/// Applies the included fields of `req` over `current` with the checks of
/// E-097 (all or nothing): the result is what the slave keeps.
pub fn apply_set_ip(current: &IpParams, req: &IpParams) -> Result<IpParams, IpError> {
    let next = IpParams {
        mac: req.mac.or(current.mac),
        ip: req.ip.or(current.ip),
        mask: req.mask.or(current.mask),
        gateway: req.gateway.or(current.gateway),
        dns: req.dns.or(current.dns),
        dns_name: req.dns_name.or(current.dns_name),
    };
    if let Some(mac) = req.mac {
        if mac.first().is_some_and(|b| b & 1 != 0) || mac == [0; 6] {
            return Err(IpError::Mac);
        }
    }
    if let Some(mask) = next.mask {
        if prefix_len(mask).is_none_or(|p| p > 30) {
            return Err(IpError::BadMask);
        }
    }
    if let Some(ip) = next.ip {
        // a multicast (224/4) address cannot be an interface's address
        let multicast = ip.first().is_some_and(|a| (224..=239).contains(a));
        let ok = !multicast
            && match next.mask {
                Some(mask) => is_host(ip, mask),
                // no mask known: only the all-zero and all-ones addresses are refused
                None => ip != [0; 4] && ip != [255; 4],
            };
        if !ok {
            return Err(IpError::HostAddress);
        }
    }
    if let (Some(gw), Some(ip), Some(mask)) = (next.gateway, next.ip, next.mask) {
        // 0.0.0.0 = no gateway
        let m = u32::from_be_bytes(mask);
        let same_net = u32::from_be_bytes(gw) & m == u32::from_be_bytes(ip) & m;
        if gw != [0; 4] && !(same_net && is_host(gw, mask)) {
            return Err(IpError::Gateway);
        }
    }
    Ok(next)
}
