//! The LLDP agent's counters (IEEE 802.1AB-2005 10.5.2, LLDP-MIB lldpStatistics, P-038):
//! frames sent and received per port, malformed LLDPDUs, reserved TLV types, and the
//! remote table's inserts and ageouts. Plain saturating `u32`s; time as an argument.

use nanos::Nanos;

use crate::model;

const PORTS: usize = model::PORTS as usize;

/// One port's receive counters (lldpStatsRxPortEntry).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Rx {
    /// LLDPDUs received (lldpStatsRxPortFramesTotal), malformed ones included.
    pub frames: u32,
    /// Malformed LLDPDUs discarded (lldpStatsRxPortFramesDiscardedTotal).
    pub discarded: u32,
    /// LLDPDUs with a detectable error (lldpStatsRxPortFramesInErrors).
    pub errors: u32,
    /// TLVs of a reserved type (9…126) in accepted LLDPDUs (lldpStatsRxPortTLVsUnrecognizedTotal).
    pub tlvs_unrecognized: u32,
    /// Neighbours forgotten because their TTL ran out (lldpStatsRxPortAgeoutsTotal).
    pub ageouts: u32,
}

/// The counters of all ports and the remote table.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// LLDPDUs sent per port (lldpStatsTxPortFramesTotal).
    pub tx: [u32; PORTS],
    /// Receive counters per port.
    pub rx: [Rx; PORTS],
    /// Neighbours added to the remote table (lldpStatsRemTablesInserts).
    pub inserts: u32,
    /// Neighbours aged out of it (lldpStatsRemTablesAgeouts).
    pub ageouts: u32,
    /// When the remote table last changed (lldpStatsRemTablesLastChangeTime).
    pub last_change: Option<Nanos>,
}

fn inc(c: &mut u32) {
    *c = c.saturating_add(1);
}

/// TLVs of a reserved type (9…126) in an LLDPDU, up to End or the first that does not fit.
fn reserved_tlvs(mut rest: &[u8]) -> u32 {
    let mut n = 0u32;
    while let (Some(&a), Some(&b)) = (rest.first(), rest.get(1)) {
        let t = a >> 1;
        let len = usize::from(u16::from_be_bytes([a, b]) & 0x01FF);
        if t == 0 {
            break;
        }
        if (9..=126).contains(&t) {
            n = n.saturating_add(1);
        }
        match rest.get(2 + len..) {
            Some(r) => rest = r,
            None => break,
        }
    }
    n
}

impl Stats {
    /// An LLDPDU went out on `port` (1-based).
    pub fn sent(&mut self, port: u16) {
        if let Some(c) = self.tx.get_mut(usize::from(port).wrapping_sub(1)) {
            inc(c);
        }
    }

    /// An LLDPDU came in on `port`: `payload` as received, `accepted` whether it parsed,
    /// `inserted` whether it added a neighbour that was not there.
    pub fn received(&mut self, port: u16, payload: &[u8], accepted: bool, inserted: bool, now: Nanos) {
        let Some(rx) = self.rx.get_mut(usize::from(port).wrapping_sub(1)) else {
            return;
        };
        inc(&mut rx.frames);
        if !accepted {
            inc(&mut rx.discarded);
            inc(&mut rx.errors);
            return;
        }
        rx.tlvs_unrecognized = rx.tlvs_unrecognized.saturating_add(reserved_tlvs(payload));
        if inserted {
            inc(&mut self.inserts);
            self.last_change = Some(now);
        }
    }

    /// The neighbours of the ports in `aged` (bit 0 port 1) ran out at `now`.
    pub fn aged_out(&mut self, aged: u8, now: Nanos) {
        for (i, rx) in self.rx.iter_mut().enumerate() {
            if aged & (1 << i) != 0 {
                inc(&mut rx.ageouts);
                inc(&mut self.ageouts);
                self.last_change = Some(now);
            }
        }
    }
}
