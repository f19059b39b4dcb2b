//! [`SimLink`]: the script's datagrams into a [`Simulation`], one frame each.

use super::Link;
use crate::frame::{ECAT_HEADER_LEN, ETHERNET_HEADER_LEN, ETHERTYPE_ETHERCAT};
use crate::sim::Simulation;

/// Wraps each datagram in an Ethernet frame and passes it down the line
/// (the host tests of the script, the fuzz targets' line in Op).
pub struct SimLink<'a>(pub &'a mut Simulation);

impl Link for SimLink<'_> {
    fn transfer(&mut self, datagram: &mut [u8]) {
        let mut f = std::vec![0xFFu8; 6];
        f.extend_from_slice(&[0x02, 0, 0, 0, 0, 1]);
        f.extend_from_slice(&ETHERTYPE_ETHERCAT.to_be_bytes());
        f.extend_from_slice(&(datagram.len() as u16 | 0x1000).to_le_bytes());
        f.extend_from_slice(datagram);
        self.0.exchange(&mut f);
        let off = ETHERNET_HEADER_LEN + ECAT_HEADER_LEN;
        if let Some(back) = f.get(off..off + datagram.len()) {
            datagram.copy_from_slice(back);
        }
    }
}
