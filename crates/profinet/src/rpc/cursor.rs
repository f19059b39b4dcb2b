//! Checked byte cursors: every read and write is bounds-checked and returns
//! `None` past the end, never panics. Multi-byte integers follow the cursor's
//! [`Endian`] (DCE/RPC's `drep` for the RPC header and NDR, big-endian for the
//! PROFINET blocks inside).

/// Byte order of multi-byte integers.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Endian {
    /// Most significant byte first (network order; PROFINET blocks).
    #[default]
    Big,
    /// Least significant byte first.
    Little,
}

/// A reading cursor over a byte slice.
#[derive(Clone, Debug)]
pub struct Reader<'a> {
    buf: &'a [u8],
    pos: usize,
    endian: Endian,
}

impl<'a> Reader<'a> {
    /// A reader at the start of `buf`.
    pub fn new(buf: &'a [u8], endian: Endian) -> Reader<'a> {
        Reader { buf, pos: 0, endian }
    }

    /// Bytes read so far.
    pub fn pos(&self) -> usize {
        self.pos
    }

    /// Bytes left.
    pub fn remaining(&self) -> usize {
        self.buf.len().saturating_sub(self.pos)
    }

    /// The unread rest.
    pub fn rest(&self) -> &'a [u8] {
        self.buf.get(self.pos..).unwrap_or(&[])
    }

    /// The next `n` bytes.
    pub fn bytes(&mut self, n: usize) -> Option<&'a [u8]> {
        let end = self.pos.checked_add(n)?;
        let s = self.buf.get(self.pos..end)?;
        self.pos = end;
        Some(s)
    }

    /// The next `N` bytes as an array.
    pub fn array<const N: usize>(&mut self) -> Option<[u8; N]> {
        let mut a = [0u8; N];
        a.copy_from_slice(self.bytes(N)?);
        Some(a)
    }

    /// Skips `n` bytes.
    pub fn skip(&mut self, n: usize) -> Option<()> {
        self.bytes(n).map(|_| ())
    }

    /// Skips to the next multiple of `n` counted from the start of the buffer.
    pub fn align(&mut self, n: usize) -> Option<()> {
        let pad = n.checked_sub(self.pos.checked_rem(n)?)?.checked_rem(n)?;
        self.skip(pad)
    }

    /// One octet.
    pub fn u8(&mut self) -> Option<u8> {
        Some(*self.bytes(1)?.first()?)
    }

    /// A u16 in the reader's order.
    pub fn u16(&mut self) -> Option<u16> {
        let a = self.array::<2>()?;
        Some(match self.endian {
            Endian::Big => u16::from_be_bytes(a),
            Endian::Little => u16::from_le_bytes(a),
        })
    }

    /// A u32 in the reader's order.
    pub fn u32(&mut self) -> Option<u32> {
        let a = self.array::<4>()?;
        Some(match self.endian {
            Endian::Big => u32::from_be_bytes(a),
            Endian::Little => u32::from_le_bytes(a),
        })
    }
}

/// A writing cursor over a mutable byte slice.
#[derive(Debug)]
pub struct Writer<'a> {
    buf: &'a mut [u8],
    pos: usize,
    endian: Endian,
}

impl<'a> Writer<'a> {
    /// A writer at the start of `buf`.
    pub fn new(buf: &'a mut [u8], endian: Endian) -> Writer<'a> {
        Writer { buf, pos: 0, endian }
    }

    /// Bytes written so far.
    pub fn pos(&self) -> usize {
        self.pos
    }

    /// The unwritten rest of the buffer (fill it, then [`Writer::advance`]).
    pub fn rest_mut(&mut self) -> &mut [u8] {
        self.buf.get_mut(self.pos..).unwrap_or(&mut [])
    }

    /// Counts `n` bytes written through [`Writer::rest_mut`] (at most what is
    /// left); returns the count taken.
    pub fn advance(&mut self, n: usize) -> usize {
        let n = n.min(self.buf.len().saturating_sub(self.pos));
        self.pos += n;
        n
    }

    fn slot(&mut self, n: usize) -> Option<&mut [u8]> {
        let end = self.pos.checked_add(n)?;
        let s = self.buf.get_mut(self.pos..end)?;
        self.pos = end;
        Some(s)
    }

    /// Writes `b`.
    pub fn bytes(&mut self, b: &[u8]) -> Option<()> {
        self.slot(b.len())?.copy_from_slice(b);
        Some(())
    }

    /// Writes `n` zero octets.
    pub fn zeros(&mut self, n: usize) -> Option<()> {
        self.slot(n)?.fill(0);
        Some(())
    }

    /// Zero-pads to the next multiple of `n` counted from the start.
    pub fn align(&mut self, n: usize) -> Option<()> {
        let pad = n.checked_sub(self.pos.checked_rem(n)?)?.checked_rem(n)?;
        self.zeros(pad)
    }

    /// Writes one octet.
    pub fn u8(&mut self, v: u8) -> Option<()> {
        self.bytes(&[v])
    }

    /// Writes a u16 in the writer's order.
    pub fn u16(&mut self, v: u16) -> Option<()> {
        let b = match self.endian {
            Endian::Big => v.to_be_bytes(),
            Endian::Little => v.to_le_bytes(),
        };
        self.bytes(&b)
    }

    /// Writes a u32 in the writer's order.
    pub fn u32(&mut self, v: u32) -> Option<()> {
        let b = match self.endian {
            Endian::Big => v.to_be_bytes(),
            Endian::Little => v.to_le_bytes(),
        };
        self.bytes(&b)
    }

    /// Overwrites a u16 at `at` (already written), in the cursor's order.
    pub fn patch_u16(&mut self, at: usize, v: u16) -> Option<()> {
        let b = match self.endian {
            Endian::Big => v.to_be_bytes(),
            Endian::Little => v.to_le_bytes(),
        };
        self.patch(at, b)
    }

    /// Overwrites a u32 at `at` (already written), in the cursor's order.
    pub fn patch_u32(&mut self, at: usize, v: u32) -> Option<()> {
        let b = match self.endian {
            Endian::Big => v.to_be_bytes(),
            Endian::Little => v.to_le_bytes(),
        };
        self.patch(at, b)
    }

    /// Overwrites the `N` bytes at `at` (already written).
    fn patch<const N: usize>(&mut self, at: usize, b: [u8; N]) -> Option<()> {
        self.buf.get_mut(at..at.checked_add(N)?)?.copy_from_slice(&b);
        Some(())
    }
}
