//! An IEEE 802.3 clause-22 PHY over MDIO: find it, reset it, advertise
//! 10/100 half/full duplex with auto-negotiation, and read the resolved
//! link. Only the standard registers (0, 1, 2, 3, 4, 5) are used, so any
//! 10/100 PHY (the boards' KSZ8081, DP83848, LAN8720 class) is served.

use crate::{Error, Eth, Link, Regs};

/// Basic mode control.
pub const BMCR: u8 = 0;
/// Basic mode status.
pub const BMSR: u8 = 1;
/// PHY identifier 1.
pub const PHYID1: u8 = 2;
/// PHY identifier 2.
pub const PHYID2: u8 = 3;
/// Auto-negotiation advertisement.
pub const ANAR: u8 = 4;
/// Auto-negotiation link partner ability.
pub const ANLPAR: u8 = 5;

/// BMCR: reset (self-clearing).
pub const BMCR_RESET: u16 = 1 << 15;
/// BMCR: 100 Mbit/s when auto-negotiation is off.
pub const BMCR_SPEED_100: u16 = 1 << 13;
/// BMCR: auto-negotiation enable.
pub const BMCR_ANEN: u16 = 1 << 12;
/// BMCR: restart auto-negotiation.
pub const BMCR_RESTART_AN: u16 = 1 << 9;
/// BMCR: full duplex when auto-negotiation is off.
pub const BMCR_FULL_DUPLEX: u16 = 1 << 8;
/// BMSR: auto-negotiation complete.
pub const BMSR_AN_COMPLETE: u16 = 1 << 5;
/// BMSR: link up (latched low: read twice for the current state).
pub const BMSR_LINK: u16 = 1 << 2;
/// ANAR/ANLPAR: 100BASE-TX full duplex.
pub const AN_100_FULL: u16 = 1 << 8;
/// ANAR/ANLPAR: 100BASE-TX.
pub const AN_100_HALF: u16 = 1 << 7;
/// ANAR/ANLPAR: 10BASE-T full duplex.
pub const AN_10_FULL: u16 = 1 << 6;
/// ANAR/ANLPAR: 10BASE-T.
pub const AN_10_HALF: u16 = 1 << 5;
/// ANAR: selector IEEE 802.3.
pub const AN_SELECTOR_802_3: u16 = 1;

/// Register access to PHYs.
pub trait Mdio {
    /// Reads `reg` of the PHY at `phy`.
    fn read(&mut self, phy: u8, reg: u8) -> Result<u16, Error>;
    /// Writes `reg` of the PHY at `phy`.
    fn write(&mut self, phy: u8, reg: u8, value: u16) -> Result<(), Error>;
}

impl<R: Regs, const RX: usize, const TX: usize> Mdio for Eth<'_, R, RX, TX> {
    fn read(&mut self, phy: u8, reg: u8) -> Result<u16, Error> {
        self.mdio_read(phy, reg)
    }
    fn write(&mut self, phy: u8, reg: u8, value: u16) -> Result<(), Error> {
        self.mdio_write(phy, reg, value)
    }
}

/// The PHY's 32-bit identifier (OUI, model, revision); [`Error::NoPhy`]
/// when nothing answers (an undriven MDIO reads all ones).
pub fn id(m: &mut impl Mdio, phy: u8) -> Result<u32, Error> {
    let id = u32::from(m.read(phy, PHYID1)?) << 16 | u32::from(m.read(phy, PHYID2)?);
    if id == 0 || id == u32::MAX {
        Err(Error::NoPhy)
    } else {
        Ok(id)
    }
}

/// The first address from `preferred`, then 0…31, where a PHY answers,
/// with its identifier.
pub fn find(m: &mut impl Mdio, preferred: u8) -> Result<(u8, u32), Error> {
    let mut last = Error::NoPhy;
    for a in core::iter::once(preferred & 0x1F).chain(0..32) {
        match id(m, a) {
            Ok(i) => return Ok((a, i)),
            Err(e) => last = e,
        }
    }
    Err(last)
}

/// Resets the PHY, advertises 10/100 half/full duplex and starts
/// auto-negotiation. `polls` bounds the wait for the reset (IEEE 802.3:
/// at most 0.5 s).
pub fn bring_up(m: &mut impl Mdio, phy: u8, polls: u32) -> Result<(), Error> {
    m.write(phy, BMCR, BMCR_RESET)?;
    let mut done = false;
    for _ in 0..polls {
        if m.read(phy, BMCR)? & BMCR_RESET == 0 {
            done = true;
            break;
        }
    }
    if !done {
        return Err(Error::PhyResetTimeout);
    }
    m.write(
        phy,
        ANAR,
        AN_100_FULL | AN_100_HALF | AN_10_FULL | AN_10_HALF | AN_SELECTOR_802_3,
    )?;
    m.write(phy, BMCR, BMCR_ANEN | BMCR_RESTART_AN)
}

/// The link now: `None` while it is down or auto-negotiation runs; else the
/// best mode both ends advertise (or BMCR's forced mode without
/// auto-negotiation).
pub fn link(m: &mut impl Mdio, phy: u8) -> Result<Option<Link>, Error> {
    // the link bit latches low: the first read reports a drop since the last one
    let _ = m.read(phy, BMSR)?;
    let bmsr = m.read(phy, BMSR)?;
    if bmsr & BMSR_LINK == 0 {
        return Ok(None);
    }
    let bmcr = m.read(phy, BMCR)?;
    if bmcr & BMCR_ANEN == 0 {
        return Ok(Some(Link {
            speed_100: bmcr & BMCR_SPEED_100 != 0,
            full_duplex: bmcr & BMCR_FULL_DUPLEX != 0,
        }));
    }
    if bmsr & BMSR_AN_COMPLETE == 0 {
        return Ok(None);
    }
    let common = m.read(phy, ANAR)? & m.read(phy, ANLPAR)?;
    Ok(Some(resolve(common)))
}

/// The highest common mode of IEEE 802.3 Annex 28B's priority order.
pub fn resolve(common: u16) -> Link {
    let (speed_100, full_duplex) = if common & AN_100_FULL != 0 {
        (true, true)
    } else if common & AN_100_HALF != 0 {
        (true, false)
    } else if common & AN_10_FULL != 0 {
        (false, true)
    } else {
        (false, false)
    };
    Link {
        speed_100,
        full_duplex,
    }
}
