//! Reassembly of incoming Ethernet frames from EoE fragments and
//! fragmentation of outgoing ones (one fragment per mailbox message).

use super::{EoeHeader, HEADER_LEN, MAX_FRAME, MIN_FRAME, TIME_STAMP_LEN};

/// Why a fragment was refused; the frame being assembled is dropped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FragmentError {
    /// A later fragment without a frame in assembly.
    NoFrame,
    /// Fragment number out of sequence.
    Sequence,
    /// Frame number differs from the frame in assembly.
    FrameNumber,
    /// Offset does not match the bytes received so far.
    Offset,
    /// More data than the complete size announced (or than [`MAX_FRAME`]).
    TooLong,
    /// The finished frame is shorter than an Ethernet header (or than its
    /// time stamp).
    TooShort,
}

/// Reassembly of one Ethernet frame from EoE fragments into a fixed buffer.
#[derive(Clone)]
pub struct Reassembly {
    buf: [u8; MAX_FRAME],
    len: usize,
    /// Announced complete size, bytes (32-byte blocks × 32, capped at the buffer).
    size: usize,
    next_fragment: u8,
    frame_number: u8,
    active: bool,
    /// Frames dropped (bad or out-of-order fragments, interrupted frames).
    dropped: u32,
}

impl Default for Reassembly {
    fn default() -> Self {
        Self::new()
    }
}

impl Reassembly {
    /// Empty.
    pub const fn new() -> Self {
        Self {
            buf: [0; MAX_FRAME],
            len: 0,
            size: 0,
            next_fragment: 0,
            frame_number: 0,
            active: false,
            dropped: 0,
        }
    }

    /// Drops the frame in assembly (not counted).
    pub fn reset(&mut self) {
        self.active = false;
        self.len = 0;
    }

    /// Whether a frame is being assembled.
    pub fn active(&self) -> bool {
        self.active
    }

    /// Frames dropped so far.
    pub fn dropped(&self) -> u32 {
        self.dropped
    }

    /// Takes one fragment (`data`: the mailbox data after the EoE header).
    /// Returns the length of the finished frame (then in [`frame`](Self::frame))
    /// after the last fragment. A bad fragment drops the frame in assembly
    /// and counts it; a fragment 0 while a frame is in assembly drops that
    /// frame (counted) and starts the new one.
    pub fn push(&mut self, h: &EoeHeader, data: &[u8]) -> Result<Option<usize>, FragmentError> {
        let r = self.push_inner(h, data);
        if r.is_err() {
            self.fail();
        }
        r
    }

    fn fail(&mut self) {
        self.dropped = self.dropped.wrapping_add(1);
        self.reset();
    }

    fn push_inner(&mut self, h: &EoeHeader, data: &[u8]) -> Result<Option<usize>, FragmentError> {
        let blocks = usize::from(h.size_or_offset()) * 32;
        if h.fragment_number() == 0 {
            if self.active {
                // the previous frame never finished
                self.fail();
            }
            if blocks == 0 {
                return Err(FragmentError::TooLong);
            }
            self.active = true;
            self.len = 0;
            self.size = blocks.min(MAX_FRAME);
            self.frame_number = h.frame_number();
            self.next_fragment = 0;
        } else {
            if !self.active {
                // counted, nothing to drop
                return Err(FragmentError::NoFrame);
            }
            if h.fragment_number() != self.next_fragment {
                return Err(FragmentError::Sequence);
            }
            if h.frame_number() != self.frame_number {
                return Err(FragmentError::FrameNumber);
            }
            if blocks != self.len {
                return Err(FragmentError::Offset);
            }
        }
        let end = self.len.checked_add(data.len()).ok_or(FragmentError::TooLong)?;
        // the time stamp of the last fragment may exceed the announced size
        let stamp = if h.last && h.time_appended {
            TIME_STAMP_LEN
        } else {
            0
        };
        if end > self.size.saturating_add(stamp) || end > MAX_FRAME + stamp {
            return Err(FragmentError::TooLong);
        }
        if !h.last {
            let dst = self.buf.get_mut(self.len..end).ok_or(FragmentError::TooLong)?;
            dst.copy_from_slice(data);
            self.len = end;
            self.next_fragment = (self.next_fragment + 1) & 0x3F;
            return Ok(None);
        }
        let data = data
            .get(..data.len().checked_sub(stamp).ok_or(FragmentError::TooShort)?)
            .ok_or(FragmentError::TooShort)?;
        let end = self.len + data.len();
        let dst = self.buf.get_mut(self.len..end).ok_or(FragmentError::TooLong)?;
        dst.copy_from_slice(data);
        if end < MIN_FRAME {
            return Err(FragmentError::TooShort);
        }
        self.len = end;
        self.active = false;
        Ok(Some(end))
    }

    /// The last finished frame.
    pub fn frame(&self) -> &[u8] {
        self.buf.get(..self.len).unwrap_or_default()
    }
}

/// Fragmentation of one outgoing Ethernet frame into mailbox-sized EoE
/// fragments (one per mailbox message).
#[derive(Clone)]
pub struct Fragmenter {
    buf: [u8; MAX_FRAME],
    len: usize,
    sent: usize,
    fragment: u8,
    frame_number: u8,
    active: bool,
}

impl Default for Fragmenter {
    fn default() -> Self {
        Self::new()
    }
}

impl Fragmenter {
    /// Idle.
    pub const fn new() -> Self {
        Self {
            buf: [0; MAX_FRAME],
            len: 0,
            sent: 0,
            fragment: 0,
            frame_number: 0,
            active: false,
        }
    }

    /// Whether a frame is being sent.
    pub fn active(&self) -> bool {
        self.active
    }

    /// Drops the frame being sent.
    pub fn reset(&mut self) {
        self.active = false;
    }

    /// Loads the next frame from `fill` (which writes it into the buffer
    /// and returns its length) when idle; a length of 0 or beyond the
    /// buffer sends nothing. Returns whether a frame is being sent.
    pub fn load(&mut self, fill: impl FnOnce(&mut [u8]) -> Option<usize>) -> bool {
        if !self.active {
            if let Some(n) = fill(&mut self.buf).filter(|&n| n > 0 && n <= MAX_FRAME) {
                self.len = n;
                self.sent = 0;
                self.fragment = 0;
                self.frame_number = (self.frame_number + 1) & 0x0F;
                self.active = true;
            }
        }
        self.active
    }

    /// Writes the next fragment (EoE header + data) into `out` (the mailbox
    /// data area) and returns its length; `None` when idle or `out` cannot
    /// hold a header and 32 bytes (the frame is then dropped). Fragments but
    /// the last carry a multiple of 32 bytes.
    pub fn next(&mut self, out: &mut [u8]) -> Option<usize> {
        if !self.active {
            return None;
        }
        let room = out.len().saturating_sub(HEADER_LEN);
        let rest = self.len.saturating_sub(self.sent);
        let (n, last) = if rest <= room {
            (rest, true)
        } else {
            (room / 32 * 32, false)
        };
        if n == 0 && !last {
            self.active = false;
            return None;
        }
        let size_or_offset = if self.fragment == 0 {
            self.len.div_ceil(32)
        } else {
            self.sent / 32
        };
        let h = EoeHeader::fragment(last, self.fragment, size_or_offset as u8, self.frame_number);
        let src = self.buf.get(self.sent..self.sent + n)?;
        out.get_mut(..HEADER_LEN)?.copy_from_slice(&h.to_bytes());
        out.get_mut(HEADER_LEN..HEADER_LEN + n)?.copy_from_slice(src);
        self.sent += n;
        self.fragment = (self.fragment + 1) & 0x3F;
        if last {
            self.active = false;
        }
        Some(HEADER_LEN + n)
    }
}
