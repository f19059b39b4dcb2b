//! A frame of one datagram as a master puts it on the line, for the tests
//! and fuzz targets that talk to [`Simulation::exchange`](super::Simulation::exchange)
//! without a master library.

use crate::frame::{DATAGRAM_HEADER_LEN, ECAT_HEADER_LEN, ETHERTYPE_ETHERCAT, FRAME_TYPE_COMMANDS, WKC_LEN};
use std::vec::Vec;

/// The shortest Ethernet frame without its FCS.
pub const MIN_FRAME_LEN: usize = 60;

/// One datagram frame: broadcast destination, source `mac`, the EtherCAT
/// header, the datagram (`cmd`, `index`, `adp`, `ado`, `data`, working
/// counter 0), zero-padded to `min_len` bytes ([`MIN_FRAME_LEN`] as on a
/// wire, 0 for none). `data` longer than a datagram carries (2,047 bytes)
/// is cut to that.
pub fn datagram_frame(
    mac: [u8; 6],
    cmd: u8,
    index: u8,
    adp: u16,
    ado: u16,
    data: &[u8],
    min_len: usize,
) -> Vec<u8> {
    let data = data.get(..data.len().min(0x07FF)).unwrap_or(data);
    let len = data.len() as u16;
    let mut f =
        Vec::with_capacity((14 + ECAT_HEADER_LEN + DATAGRAM_HEADER_LEN + data.len() + WKC_LEN).max(min_len));
    f.extend_from_slice(&[0xFF; 6]);
    f.extend_from_slice(&mac);
    f.extend_from_slice(&ETHERTYPE_ETHERCAT.to_be_bytes());
    let area = DATAGRAM_HEADER_LEN as u16 + len + WKC_LEN as u16;
    f.extend_from_slice(&(area | u16::from(FRAME_TYPE_COMMANDS) << 12).to_le_bytes());
    f.extend_from_slice(&[cmd, index]);
    f.extend_from_slice(&adp.to_le_bytes());
    f.extend_from_slice(&ado.to_le_bytes());
    f.extend_from_slice(&len.to_le_bytes());
    f.extend_from_slice(&[0, 0]);
    f.extend_from_slice(data);
    f.extend_from_slice(&[0, 0]);
    if f.len() < min_len {
        f.resize(min_len, 0);
    }
    f
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{Command, Datagram, ETHERNET_HEADER_LEN};

    /// The frame parses as the one datagram it was built from (E-002's
    /// frame layout), padded to the wire's minimum.
    #[test]
    fn e002_datagram_frame_parses_as_its_datagram() {
        let mac = [0x02, 0, 0, 0, 0, 0x99];
        let mut f = datagram_frame(mac, 5, 0x42, 0x1001, 0x0120, &[8, 0], MIN_FRAME_LEN);
        assert_eq!(f.len(), MIN_FRAME_LEN);
        assert_eq!(&f[6..12], &mac);
        assert_eq!(u16::from_be_bytes([f[12], f[13]]), ETHERTYPE_ETHERCAT);
        let header = u16::from_le_bytes([f[14], f[15]]);
        assert_eq!((header & 0x07FF, header >> 12), (14, 1));
        let d = Datagram::new_checked(&mut f[ETHERNET_HEADER_LEN + ECAT_HEADER_LEN..]).unwrap();
        assert_eq!(d.command(), Command::Fpwr);
        assert_eq!(
            (d.index(), d.adp(), d.ado(), d.data(), d.wkc()),
            (0x42, 0x1001, 0x0120, &[8u8, 0][..], 0)
        );
        assert!(!d.more_follows());
        let long = datagram_frame([0x10; 6], 4, 0, 0, 0, &[1; 100], 0);
        assert_eq!(long.len(), 14 + 2 + 10 + 100 + 2, "no padding asked, none added");
    }
}
