//! XMC4800 board glue of the PROFINET image: ETH0's clock, reset, port pins
//! and RMII selection, the board's identity (the power-stage gate enable is
//! the EtherCAT image's, `firmware::xmc::power`).
//!
//! NOT VERIFIED ON HARDWARE (docs/hardware.md, "ETH0 and the PHY"): the
//! reference kit KIT_XMC48_RELAX_ECAT_V1 wires its two PHYs to the EtherCAT
//! controller, not to ETH0; the RMII pins below are those of Infineon's
//! XMC4700/4800 Relax Kit Ethernet examples (PHY on P2.x/P15.8/P15.9) and
//! must be checked against the board that carries the PHY.

use drive_pn::Hardware;
use profinet::cm::{Im0, ImData};
use profinet::wire::MacAddr;

/// The interface MAC. A locally administered placeholder: a product takes
/// its MAC from production data (the kit has no MAC EEPROM).
pub const MAC: MacAddr = MacAddr([0x02, 0x00, 0x00, 0x48, 0x00, 0x50]);

/// Where the PHY is looked for first (the Relax Kit's KSZ8081RNB strap);
/// `gmac::phy::find` scans 0…31 after it.
pub const PHY_ADDR: u8 = 0;

/// The board's identity for the device.
pub fn hardware() -> Hardware {
    Hardware {
        mac: MAC,
        port_macs: [
            MacAddr([0x02, 0x00, 0x00, 0x48, 0x00, 0x51]),
            MacAddr([0x02, 0x00, 0x00, 0x48, 0x00, 0x52]),
        ],
        im0: Im0::drive("XMC4800-0001"),
        im: ImData::default(),
        // no real-time clock: the same after every start (the RPC boot time
        // should differ; a product keeps a boot counter in its flash)
        boot_time: 1,
    }
}

/// IOCR pin control: ALT1 push-pull output.
const PC_ALT1: u32 = 0b1_0001;

/// Replaces pin `pin`'s 5-bit control field in an IOCR value.
fn with_pc(v: u32, pin: u32, pc: u32) -> u32 {
    let at = 8 * (pin % 4) + 3;
    (v & !(0x1F << at)) | (pc << at)
}

/// ETH0 on: clock enabled, ungated, reset released (SCU), RMII outputs on
/// port 2 (P2.5 TX_EN, P2.8 TXD0, P2.9 TXD1, P2.7 MDC: ALT1; P2.0 MDIO under
/// the MAC's control, HWSEL HW0), the inputs selected in ETH0_CON (RXD0
/// P2.2, RXD1 P2.3, RXER P2.4: A; CLK_RMII P15.8, CRS_DV P15.9: C; MDIO
/// P2.0: B) and RMII chosen. The input pins stay inputs (reset state).
#[allow(unsafe_code)]
pub fn eth0_enable() {
    // SAFETY: fixed peripheral addresses, used only here at start (before
    // any task runs).
    let (scu_clk, scu_reset, port2, con) = unsafe {
        (
            &*xmc4800::SCU_CLK::ptr(),
            &*xmc4800::SCU_RESET::ptr(),
            &*xmc4800::PORT2::ptr(),
            &*xmc4800::ETH0_CON::ptr(),
        )
    };
    scu_clk.clkset().write(|w| w.eth0cen().set_bit());
    scu_clk.cgatclr2().write(|w| w.eth0().set_bit());
    scu_reset.prclr2().write(|w| w.eth0rs().set_bit());
    // SAFETY (bits): each value keeps the other pins' fields and sets valid
    // pin-control codes / input selections of the reference manual.
    port2
        .iocr4()
        .modify(|r, w| unsafe { w.bits(with_pc(with_pc(r.bits(), 5, PC_ALT1), 7, PC_ALT1)) });
    port2
        .iocr8()
        .modify(|r, w| unsafe { w.bits(with_pc(with_pc(r.bits(), 8, PC_ALT1), 9, PC_ALT1)) });
    // P2.0 driven by hardware peripheral 0 (ETH0 MDIO)
    port2
        .hwsel()
        .modify(|r, w| unsafe { w.bits((r.bits() & !0b11) | 0b01) });
    con.eth0_con().write(|w| unsafe {
        w.bits(
            (2 << 8) // CLK_RMII: C = P15.8
                | (2 << 10) // CRS_DV: C = P15.9
                | (1 << 22) // MDIO: B = P2.0
                | (1 << 26), // INFSEL: RMII
        )
    });
}
