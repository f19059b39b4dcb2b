//! A pcap writer (classic format, link type Ethernet, nanosecond timestamps),
//! so Wireshark's EtherCAT dissector reads what the simulator saw.

use std::io::{self, Write};

/// Writes Ethernet frames with their simulated time to a pcap stream.
pub struct PcapWriter<W: Write> {
    out: W,
}

/// Magic of a pcap file whose timestamps carry nanoseconds.
const MAGIC_NS: u32 = 0xA1B2_3C4D;
/// LINKTYPE_ETHERNET.
const LINKTYPE_ETHERNET: u32 = 1;
/// Longest frame recorded whole.
const SNAPLEN: u32 = 65_535;

impl<W: Write> PcapWriter<W> {
    /// Writes the file header.
    pub fn new(mut out: W) -> io::Result<Self> {
        out.write_all(&MAGIC_NS.to_le_bytes())?;
        out.write_all(&2u16.to_le_bytes())?; // version 2.4
        out.write_all(&4u16.to_le_bytes())?;
        out.write_all(&0i32.to_le_bytes())?; // this zone
        out.write_all(&0u32.to_le_bytes())?; // sigfigs
        out.write_all(&SNAPLEN.to_le_bytes())?;
        out.write_all(&LINKTYPE_ETHERNET.to_le_bytes())?;
        Ok(Self { out })
    }

    /// Appends one frame seen at `t_ns` nanoseconds of simulated time.
    pub fn frame(&mut self, t_ns: u64, frame: &[u8]) -> io::Result<()> {
        let len = u32::try_from(frame.len()).unwrap_or(u32::MAX);
        let sec = u32::try_from(t_ns / 1_000_000_000).unwrap_or(u32::MAX);
        let nsec = (t_ns % 1_000_000_000) as u32;
        self.out.write_all(&sec.to_le_bytes())?;
        self.out.write_all(&nsec.to_le_bytes())?;
        self.out.write_all(&len.min(SNAPLEN).to_le_bytes())?;
        self.out.write_all(&len.to_le_bytes())?;
        self.out.write_all(frame.get(..SNAPLEN as usize).unwrap_or(frame))
    }

    /// Flushes the underlying stream.
    pub fn flush(&mut self) -> io::Result<()> {
        self.out.flush()
    }

    /// The underlying stream.
    pub fn into_inner(self) -> W {
        self.out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_and_record_layout() {
        let mut w = PcapWriter::new(Vec::new()).unwrap();
        w.frame(1_500_000_123, &[0xAA; 60]).unwrap();
        let b = w.into_inner();
        assert_eq!(b.len(), 24 + 16 + 60);
        assert_eq!(&b[0..4], &MAGIC_NS.to_le_bytes());
        assert_eq!(u32::from_le_bytes(b[20..24].try_into().unwrap()), 1);
        assert_eq!(u32::from_le_bytes(b[24..28].try_into().unwrap()), 1); // seconds
        assert_eq!(u32::from_le_bytes(b[28..32].try_into().unwrap()), 500_000_123); // ns
        assert_eq!(u32::from_le_bytes(b[32..36].try_into().unwrap()), 60);
    }
}
