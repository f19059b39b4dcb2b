//! Checked BER views: a reader over a borrowed slice and a writer into a borrowed buffer.
//! Every access is bounds-checked; a malformed encoding is `None`, never a panic.

/// Most sub-identifiers an OID may have here (longer OIDs are rejected as malformed).
pub const MAX_OID: usize = 32;

/// An object identifier held inline.
#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub struct Oid {
    arcs: [u32; MAX_OID],
    len: usize,
}

impl Oid {
    /// The empty OID.
    pub const fn empty() -> Self {
        Self {
            arcs: [0; MAX_OID],
            len: 0,
        }
    }
    /// From arcs; `None` when longer than [`MAX_OID`].
    pub fn from_arcs(a: &[u32]) -> Option<Self> {
        let mut o = Self::empty();
        for &x in a {
            o.push(x)?;
        }
        Some(o)
    }
    /// The arcs.
    pub fn arcs(&self) -> &[u32] {
        self.arcs.get(..self.len).unwrap_or(&[])
    }
    /// Append one arc.
    pub fn push(&mut self, x: u32) -> Option<()> {
        *self.arcs.get_mut(self.len)? = x;
        self.len += 1;
        Some(())
    }
}

/// A reader over BER bytes.
pub struct Reader<'a> {
    buf: &'a [u8],
}

impl<'a> Reader<'a> {
    /// Read from `buf`.
    pub fn new(buf: &'a [u8]) -> Self {
        Self { buf }
    }
    /// Nothing left.
    pub fn is_empty(&self) -> bool {
        self.buf.is_empty()
    }
    /// Next TLV: (tag, contents). Only single-byte tags; definite lengths up to 4 bytes.
    pub fn tlv(&mut self) -> Option<(u8, &'a [u8])> {
        let (&tag, rest) = self.buf.split_first()?;
        let (&l0, mut rest) = rest.split_first()?;
        let len = if l0 < 0x80 {
            usize::from(l0)
        } else {
            let n = usize::from(l0 & 0x7f);
            if n == 0 || n > 4 {
                return None;
            }
            let (lb, r) = rest.split_at_checked(n)?;
            rest = r;
            lb.iter().fold(0usize, |a, &b| (a << 8) | usize::from(b))
        };
        let (v, r) = rest.split_at_checked(len)?;
        self.buf = r;
        Some((tag, v))
    }
    /// Next TLV with tag `want`.
    pub fn expect(&mut self, want: u8) -> Option<&'a [u8]> {
        let (t, v) = self.tlv()?;
        (t == want).then_some(v)
    }
    /// An INTEGER (tag 0x02) fitting an i32.
    pub fn int(&mut self) -> Option<i32> {
        decode_int(self.expect(0x02)?)
    }
    /// An OBJECT IDENTIFIER.
    pub fn oid(&mut self) -> Option<Oid> {
        decode_oid(self.expect(0x06)?)
    }
}

/// Two's complement INTEGER contents as i32; `None` if empty or longer than 4 bytes.
pub fn decode_int(v: &[u8]) -> Option<i32> {
    if v.is_empty() || v.len() > 4 {
        return None;
    }
    let neg = v.first().is_some_and(|&b| b & 0x80 != 0);
    let init: i32 = if neg { -1 } else { 0 };
    Some(v.iter().fold(init, |a, &b| (a << 8) | i32::from(b)))
}

/// Unsigned contents (Counter32, Gauge32, TimeTicks) as u32.
pub fn decode_uint(v: &[u8]) -> Option<u32> {
    let v = match v {
        [0, rest @ ..] if rest.len() == 4 => rest,
        _ => v,
    };
    if v.is_empty() || v.len() > 4 {
        return None;
    }
    Some(v.iter().fold(0u32, |a, &b| (a << 8) | u32::from(b)))
}

/// OID contents to arcs.
pub fn decode_oid(v: &[u8]) -> Option<Oid> {
    let mut o = Oid::empty();
    let mut acc: u32 = 0;
    let mut first = true;
    if v.last().is_some_and(|&b| b & 0x80 != 0) || v.is_empty() {
        return None;
    }
    for &b in v {
        if acc > (u32::MAX >> 7) {
            return None;
        }
        acc = (acc << 7) | u32::from(b & 0x7f);
        if b & 0x80 == 0 {
            if first {
                let (a, b) = if acc < 40 {
                    (0, acc)
                } else if acc < 80 {
                    (1, acc - 40)
                } else {
                    (2, acc - 80)
                };
                o.push(a)?;
                o.push(b)?;
                first = false;
            } else {
                o.push(acc)?;
            }
            acc = 0;
        }
    }
    Some(o)
}

/// A writer into a borrowed buffer; overflow sets a flag (checked with [`Writer::finish`]).
pub struct Writer<'a> {
    buf: &'a mut [u8],
    pos: usize,
    over: bool,
}

/// A started constructed TLV, closed with [`Writer::close`].
#[derive(Clone, Copy)]
pub struct Mark(usize);

impl<'a> Writer<'a> {
    /// Write into `buf`.
    pub fn new(buf: &'a mut [u8]) -> Self {
        Self {
            buf,
            pos: 0,
            over: false,
        }
    }
    /// Bytes written so far.
    pub fn len(&self) -> usize {
        self.pos
    }
    /// Nothing written.
    pub fn is_empty(&self) -> bool {
        self.pos == 0
    }
    /// Rewind to `len` bytes (drops what came after).
    pub fn truncate(&mut self, len: usize) {
        if len <= self.pos {
            self.pos = len;
            self.over = false;
        }
    }
    /// True while everything fitted.
    pub fn ok(&self) -> bool {
        !self.over
    }
    /// Length written, or `None` if the buffer overflowed.
    pub fn finish(self) -> Option<usize> {
        (!self.over).then_some(self.pos)
    }
    fn byte(&mut self, b: u8) {
        match self.buf.get_mut(self.pos) {
            Some(s) => {
                *s = b;
                self.pos += 1;
            }
            None => self.over = true,
        }
    }
    fn bytes(&mut self, b: &[u8]) {
        for &x in b {
            self.byte(x);
        }
    }
    fn len_field(&mut self, n: usize) {
        if n < 0x80 {
            self.byte(n as u8);
        } else if n < 0x100 {
            self.bytes(&[0x81, n as u8]);
        } else {
            self.bytes(&[0x82, (n >> 8) as u8, n as u8]);
        }
    }
    /// Primitive TLV.
    pub fn prim(&mut self, tag: u8, v: &[u8]) {
        self.byte(tag);
        self.len_field(v.len());
        self.bytes(v);
    }
    /// Open a constructed TLV (length patched at close, always 3-byte long form).
    pub fn open(&mut self, tag: u8) -> Mark {
        self.byte(tag);
        let m = Mark(self.pos);
        self.bytes(&[0x82, 0, 0]);
        m
    }
    /// Close a constructed TLV.
    pub fn close(&mut self, m: Mark) {
        if self.over {
            return;
        }
        let n = self.pos.saturating_sub(m.0 + 3);
        if let Some(s) = self.buf.get_mut(m.0 + 1..m.0 + 3) {
            s.copy_from_slice(&(n as u16).to_be_bytes());
        }
        if n > 0xffff {
            self.over = true;
        }
    }
    /// INTEGER (or an application integer type with `tag`).
    pub fn int(&mut self, tag: u8, x: i32) {
        let b = x.to_be_bytes();
        let mut s = 0;
        while s < 3 {
            let (hi, nx) = (b.get(s).copied().unwrap_or(0), b.get(s + 1).copied().unwrap_or(0));
            if (hi == 0 && nx & 0x80 == 0) || (hi == 0xff && nx & 0x80 != 0) {
                s += 1;
            } else {
                break;
            }
        }
        self.prim(tag, b.get(s..).unwrap_or(&[]));
    }
    /// Unsigned application type (Counter32, Gauge32, TimeTicks).
    pub fn uint(&mut self, tag: u8, x: u32) {
        let mut b = [0u8; 5];
        if let Some(t) = b.get_mut(1..) {
            t.copy_from_slice(&x.to_be_bytes());
        }
        let mut s = 0;
        while s < 4 && b.get(s) == Some(&0) && b.get(s + 1).is_some_and(|&n| n & 0x80 == 0) {
            s += 1;
        }
        self.prim(tag, b.get(s..).unwrap_or(&[]));
    }
    /// OBJECT IDENTIFIER.
    pub fn oid(&mut self, o: &[u32]) {
        let mut tmp = [0u8; MAX_OID * 5];
        let mut n = 0;
        let put = |tmp: &mut [u8], n: &mut usize, x: u32| {
            let mut groups = [0u8; 5];
            let mut g = 0;
            let mut v = x;
            loop {
                if let Some(s) = groups.get_mut(g) {
                    *s = (v & 0x7f) as u8;
                }
                g += 1;
                v >>= 7;
                if v == 0 || g >= 5 {
                    break;
                }
            }
            for i in (0..g).rev() {
                let more = if i > 0 { 0x80 } else { 0 };
                if let (Some(d), Some(s)) = (tmp.get_mut(*n), groups.get(i)) {
                    *d = s | more;
                }
                *n += 1;
            }
        };
        match o {
            [a, b, rest @ ..] => {
                put(&mut tmp, &mut n, a.saturating_mul(40).saturating_add(*b));
                for &x in rest {
                    put(&mut tmp, &mut n, x);
                }
            }
            [a] => put(&mut tmp, &mut n, a.saturating_mul(40)),
            [] => {}
        }
        self.prim(0x06, tmp.get(..n).unwrap_or(&[]));
    }
}
