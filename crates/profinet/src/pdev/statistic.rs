//! PDPortStatistic (index 0x8072, block 0x0251 version 1.0) of the interface
//! subslot 0x8000 and each port: the interface counters of RFC 2863 as
//! IEC 61158-6-10 lists them, each a wrapping u32 since the start.
//!
//! | counter | interface 0x8000 | port 1 (0x8001) | port 2 (0x8002) |
//! |---|---|---|---|
//! | ifInOctets | every received frame's octets | the same (the device has one receive path, on port 1) | 0 |
//! | ifOutOctets | every sent frame's octets | all but port 2's LLDP frames | its LLDP frames |
//! | ifInDiscards | 0: no frame is dropped for want of a buffer | 0 | 0 |
//! | ifOutDiscards | 0 | 0 | 0 |
//! | ifInErrors | frames too short for an Ethernet header | the same | 0 |
//! | ifOutErrors | 0: a send does not fail | 0 | 0 |
//!
//! Read only: a write is "access denied".

use super::Pdev;
use crate::cm::ndr::emit_block;
use crate::model;
use crate::rpc::cursor::Writer;

/// Block type of PDPortStatistic.
pub const PD_PORT_STATISTIC: u16 = 0x0251;

/// The counters of one submodule.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counters {
    /// ifInOctets.
    pub in_octets: u32,
    /// ifOutOctets.
    pub out_octets: u32,
    /// ifInDiscards.
    pub in_discards: u32,
    /// ifOutDiscards.
    pub out_discards: u32,
    /// ifInErrors.
    pub in_errors: u32,
    /// ifOutErrors.
    pub out_errors: u32,
}

/// What the device counted: the interface's counters and each port's LLDP
/// octets sent.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Statistics {
    /// The interface.
    pub interface: Counters,
    /// LLDP octets sent per port.
    pub lldp_out: [u32; model::PORTS as usize],
}

fn add(c: &mut u32, n: usize) {
    *c = c.wrapping_add(u32::try_from(n).unwrap_or(u32::MAX));
}

impl Pdev {
    /// A frame of `len` octets was received (`malformed`: too short for an
    /// Ethernet header).
    pub fn count_in(&mut self, len: usize, malformed: bool) {
        add(&mut self.stats.interface.in_octets, len);
        if malformed {
            add(&mut self.stats.interface.in_errors, 1);
        }
    }

    /// Frames of `len` octets in all were sent.
    pub fn count_out(&mut self, len: usize) {
        add(&mut self.stats.interface.out_octets, len);
    }

    /// An LLDP frame of `len` octets went out on `port` (1-based; also
    /// counted by [`Pdev::count_out`]).
    pub fn count_lldp(&mut self, port: u16, len: usize) {
        if let Some(c) = self.stats.lldp_out.get_mut(usize::from(port).wrapping_sub(1)) {
            add(c, len);
        }
    }

    /// The counters of `subslot` (0x8000 or a port's), `None` for others.
    pub fn counters(&self, subslot: u16) -> Option<Counters> {
        let i = self.stats.interface;
        match subslot {
            0x8000 => Some(i),
            0x8001 => {
                let others = self
                    .stats
                    .lldp_out
                    .iter()
                    .skip(1)
                    .fold(0u32, |a, &b| a.wrapping_add(b));
                Some(Counters {
                    out_octets: i.out_octets.wrapping_sub(others),
                    ..i
                })
            }
            s => {
                let port = s.checked_sub(0x8001)?;
                let out = *self.stats.lldp_out.get(usize::from(port))?;
                Some(Counters {
                    out_octets: out,
                    ..Counters::default()
                })
            }
        }
    }
}

/// Writes the PDPortStatistic block of `c`.
pub fn emit(w: &mut Writer<'_>, c: &Counters) -> Option<()> {
    emit_block(w, PD_PORT_STATISTIC, |w| {
        w.zeros(2)?;
        for v in [
            c.in_octets,
            c.out_octets,
            c.in_discards,
            c.out_discards,
            c.in_errors,
            c.out_errors,
        ] {
            w.u32(v)?;
        }
        Some(())
    })
}
