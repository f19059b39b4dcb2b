//! A pcap writer (classic format, link type Ethernet, nanosecond timestamps),
//! so Wireshark's EtherCAT dissector reads what the simulator saw.

use nanos::Nanos;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::Path;

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

    /// Appends one frame seen at simulated time `t`.
    pub fn frame(&mut self, t: Nanos, frame: &[u8]) -> io::Result<()> {
        let t_ns = t.as_ns();
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

/// A pcap recording in progress: the header is written and flushed when it is
/// created, so an unwritable file fails at once, before any run; the first
/// error of a later write is kept ([`Recording::error`]) and returned by
/// [`Recording::flush`], so a run can never end claiming a recording it lost.
pub struct Recording<W: Write = BufWriter<File>> {
    writer: PcapWriter<W>,
    error: Option<io::Error>,
}

impl Recording {
    /// Creates (truncates) the file at `path` and writes its header.
    pub fn create(path: &Path) -> io::Result<Self> {
        Self::new(BufWriter::new(File::create(path)?))
    }
}

impl<W: Write> Recording<W> {
    /// Writes the header to `out` and flushes it.
    pub fn new(out: W) -> io::Result<Self> {
        let mut writer = PcapWriter::new(out)?;
        writer.flush()?;
        Ok(Self { writer, error: None })
    }

    /// Appends one frame seen at `t`; after an error nothing more is written.
    pub fn frame(&mut self, t: Nanos, frame: &[u8]) {
        if self.error.is_none() {
            self.error = self.writer.frame(t, frame).err();
        }
    }

    /// The first write error, if any.
    pub fn error(&self) -> Option<&io::Error> {
        self.error.as_ref()
    }

    /// Flushes the stream; the first write error if there was one.
    pub fn flush(&mut self) -> io::Result<()> {
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        self.writer.flush()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_and_record_layout() {
        let mut w = PcapWriter::new(Vec::new()).unwrap();
        w.frame(Nanos::from_ns(1_500_000_123), &[0xAA; 60]).unwrap();
        let b = w.into_inner();
        assert_eq!(b.len(), 24 + 16 + 60);
        assert_eq!(&b[0..4], &MAGIC_NS.to_le_bytes());
        assert_eq!(u32::from_le_bytes(b[20..24].try_into().unwrap()), 1);
        assert_eq!(u32::from_le_bytes(b[24..28].try_into().unwrap()), 1); // seconds
        assert_eq!(u32::from_le_bytes(b[28..32].try_into().unwrap()), 500_000_123); // ns
        assert_eq!(u32::from_le_bytes(b[32..36].try_into().unwrap()), 60);
    }

    /// A stream that takes `room` bytes, then fails (a full disk).
    struct Full {
        room: usize,
    }

    impl Write for Full {
        fn write(&mut self, b: &[u8]) -> io::Result<usize> {
            if self.room == 0 {
                return Err(io::Error::new(io::ErrorKind::StorageFull, "disk full"));
            }
            let n = b.len().min(self.room);
            self.room -= n;
            Ok(n)
        }
        fn flush(&mut self) -> io::Result<()> {
            Ok(())
        }
    }

    #[test]
    fn a_write_error_during_the_recording_is_kept_and_returned() {
        assert!(Recording::new(Full { room: 10 }).is_err(), "header does not fit");
        let mut r = Recording::new(Full {
            room: 24 + 2 * (16 + 60) + 5,
        })
        .unwrap();
        r.frame(Nanos::from_ns(1), &[0; 60]);
        r.frame(Nanos::from_ns(2), &[0; 60]);
        assert!(r.error().is_none());
        r.frame(Nanos::from_ns(3), &[0; 60]);
        assert_eq!(r.error().map(io::Error::kind), Some(io::ErrorKind::StorageFull));
        r.frame(Nanos::from_ns(4), &[0; 60]);
        assert_eq!(r.flush().map_err(|e| e.kind()), Err(io::ErrorKind::StorageFull));
    }

    #[test]
    fn an_unwritable_path_fails_at_creation() {
        let dir = std::env::temp_dir().join(format!("hil-sim-pcap-{}", std::process::id()));
        std::fs::write(&dir, b"a file, not a directory").unwrap();
        let err = Recording::create(&dir.join("a.pcap")).err();
        std::fs::remove_file(&dir).unwrap();
        assert!(err.is_some(), "a path below a regular file cannot be created");
    }
}
