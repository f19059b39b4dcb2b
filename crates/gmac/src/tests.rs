//! The driver against a register model of the MAC (reset, FIFO flush and
//! MDIO finish at once; a clause-22 PHY behind MDIO) and a model of its DMA
//! (tests hand descriptors over as the DMA would).

use super::phy::{self, Mdio};
use super::*;
use std::boxed::Box;
use std::collections::BTreeMap;
use std::vec::Vec;

#[derive(Default)]
struct Model {
    regs: BTreeMap<u32, u32>,
    writes: Vec<(u32, u32)>,
    phy_addr: u8,
    phy: [u16; 32],
    /// The DMA reset never finishes (no PHY clock).
    stuck_reset: bool,
}

impl Regs for Model {
    fn read(&mut self, offset: u32) -> u32 {
        *self.regs.get(&offset).unwrap_or(&0)
    }
    fn write(&mut self, offset: u32, value: u32) {
        self.writes.push((offset, value));
        let v = match offset {
            BUS_MODE if !self.stuck_reset => value & !BUS_SWR,
            OPERATION_MODE => value & !OP_FTF,
            STATUS => self.read(STATUS) & !(value & DMA_W1C),
            GMII_ADDRESS => {
                let pa = ((value >> MII_PA_SHIFT) & 0x1F) as u8;
                let reg = ((value >> MII_MR_SHIFT) & 0x1F) as usize;
                if value & MII_WRITE != 0 {
                    if pa == self.phy_addr {
                        let mut d = self.read(GMII_DATA) as u16;
                        if reg == 0 {
                            // reset and restart clear themselves
                            d &= !(phy::BMCR_RESET | phy::BMCR_RESTART_AN);
                        }
                        self.phy[reg] = d;
                    }
                } else {
                    let d = if pa == self.phy_addr {
                        self.phy[reg]
                    } else {
                        0xFFFF
                    };
                    self.regs.insert(GMII_DATA, u32::from(d));
                }
                value & !MII_BUSY
            }
            _ => value,
        };
        self.regs.insert(offset, v);
    }
}

fn model() -> Model {
    let mut m = Model {
        phy_addr: 1,
        ..Model::default()
    };
    m.phy[2] = 0x0022;
    m.phy[3] = 0x1561;
    m
}

fn rings() -> &'static mut Rings<4, 2> {
    Rings::init(Box::leak(Box::new(MaybeUninit::uninit())))
}

const MAC: [u8; 6] = [0x02, 0x00, 0x00, 0x12, 0x34, 0x56];

#[test]
fn new_programs_address_filter_rings_and_interrupts() {
    let mut eth = Eth::new(model(), rings(), MAC).unwrap();
    let (rx_base, tx_base) = {
        let (rx, tx) = eth.rings_mut();
        for i in 0..4 {
            assert_eq!(rx.word(i, 0), DES0_OWN, "rx {i} the DMA's");
            let end = if i == 3 { RDES1_RER } else { 0 };
            assert_eq!(rx.word(i, 1), end | BUF as u32);
            assert_ne!(rx.word(i, 2), 0);
        }
        assert_eq!(tx.word(0, 0), 0);
        assert_eq!(tx.word(1, 0), TDES0_TER);
        (desc_addr(&rx.desc), desc_addr(&tx.desc))
    };
    let r = eth.regs_mut();
    assert_eq!(r.read(MAC_ADDRESS0_HIGH), 0x5634);
    assert_eq!(r.read(MAC_ADDRESS0_LOW), 0x1200_0002);
    assert_eq!(r.read(MAC_FRAME_FILTER), FILTER_PM);
    assert_eq!(r.read(RECEIVE_DESCRIPTOR_LIST_ADDRESS), rx_base);
    assert_eq!(r.read(TRANSMIT_DESCRIPTOR_LIST_ADDRESS), tx_base);
    assert_eq!(r.read(INTERRUPT_ENABLE) & (DMA_RI | DMA_NIS), DMA_RI | DMA_NIS);
    assert_eq!(r.read(OPERATION_MODE) & (OP_ST | OP_SR), 0, "stopped until start");
    eth.start(Link {
        speed_100: true,
        full_duplex: true,
    });
    let r = eth.regs_mut();
    assert_eq!(r.read(MAC_CONFIGURATION), MAC_TE | MAC_RE | MAC_FES | MAC_DM);
    assert_eq!(r.read(OPERATION_MODE) & (OP_ST | OP_SR), OP_ST | OP_SR);
}

#[test]
fn a_dma_reset_that_never_ends_is_an_error() {
    let m = Model {
        stuck_reset: true,
        ..model()
    };
    assert_eq!(Eth::new(m, rings(), MAC).err(), Some(Error::ResetTimeout));
}

#[test]
fn received_frames_come_without_crc_errors_are_skipped_and_the_ring_wraps() {
    let mut eth = Eth::new(model(), rings(), MAC).unwrap();
    let whole = RDES0_FS | RDES0_LS;
    for round in 0..3u8 {
        {
            let (rx, _) = eth.rings_mut();
            rx.dma_receive(0, &[round; 60], whole);
            rx.dma_receive(1, &[0xEE; 60], whole | RDES0_ES);
            rx.dma_receive(2, &[round + 1; 100], whole);
            rx.dma_receive(3, &[round + 2; 64], RDES0_FS);
        }
        let mut got = Vec::new();
        let n = eth.receive(|f, _| got.push(f.to_vec()));
        assert_eq!(n, 2);
        assert_eq!(got, [std::vec![round; 60], std::vec![round + 1; 100]]);
        let (rx, _) = eth.rings_mut();
        for i in 0..4 {
            assert_eq!(rx.word(i, 0), DES0_OWN, "given back");
        }
        assert_eq!(eth.receive(|_, _| panic!("nothing new")), 0);
    }
    let s = eth.stats();
    assert_eq!((s.rx_frames, s.rx_errors), (6, 6));
    assert!(eth
        .regs_mut()
        .writes
        .iter()
        .any(|&(o, _)| o == RECEIVE_POLL_DEMAND));
}

#[test]
fn frames_go_out_in_ring_order_until_the_ring_is_full() {
    let mut eth = Eth::new(model(), rings(), MAC).unwrap();
    let mut tx = eth.transmitter();
    assert_eq!(tx.send(&[1; 60]), Ok(()));
    assert_eq!(tx.send(&[2; 42]), Ok(()));
    assert_eq!(tx.send(&[3; 60]), Err(TxError::Busy));
    assert_eq!(tx.send(&[]), Err(TxError::Length));
    assert_eq!(tx.send(&[0; BUF + 1]), Err(TxError::Length));
    let (_, ring) = eth.rings_mut();
    assert_eq!(ring.word(0, 0), DES0_OWN | TDES0_FS | TDES0_LS);
    assert_eq!(ring.word(1, 0), DES0_OWN | TDES0_FS | TDES0_LS | TDES0_TER);
    assert_eq!(ring.dma_sent(0, 0), [1; 60]);
    assert_eq!(ring.dma_sent(1, TDES0_ES), [2; 42]);
    // a frame sent while a received one is handled
    eth.rings_mut().0.dma_receive(0, &[9; 60], RDES0_FS | RDES0_LS);
    eth.receive(|f, tx| tx.send(f).unwrap());
    eth.transmitter().send(&[4; 60]).unwrap();
    assert_eq!(eth.rings_mut().1.dma_sent(0, 0), [9; 60]);
    assert_eq!(eth.rings_mut().1.dma_sent(1, 0), [4; 60]);
    let s = eth.stats();
    assert_eq!((s.tx_frames, s.tx_busy, s.tx_length, s.tx_errors), (4, 1, 2, 1));
}

#[test]
fn the_phy_is_found_reset_and_its_link_resolved() {
    let mut eth = Eth::new(model(), rings(), MAC).unwrap();
    assert_eq!(phy::id(&mut eth, 0), Err(Error::NoPhy));
    assert_eq!(phy::find(&mut eth, 0), Ok((1, 0x0022_1561)));
    phy::bring_up(&mut eth, 1, 10).unwrap();
    assert_eq!(eth.read(1, phy::BMCR).unwrap(), phy::BMCR_ANEN);
    assert_eq!(eth.read(1, phy::ANAR).unwrap(), 0x01E1);
    assert_eq!(phy::link(&mut eth, 1), Ok(None), "no link yet");
    // link up, negotiated with a 100 half-duplex partner
    eth.write(1, phy::BMSR, phy::BMSR_LINK | phy::BMSR_AN_COMPLETE)
        .unwrap();
    eth.write(1, phy::ANLPAR, phy::AN_100_HALF | phy::AN_10_FULL)
        .unwrap();
    assert_eq!(
        phy::link(&mut eth, 1),
        Ok(Some(Link {
            speed_100: true,
            full_duplex: false
        }))
    );
    assert!(!phy::resolve(phy::AN_10_HALF).speed_100);
    // MDIO frames carry address, register and the clock range
    let last = eth.regs_mut().read(GMII_ADDRESS);
    assert_eq!(last >> MII_PA_SHIFT & 0x1F, 1);
    assert_eq!(last >> MII_CR_SHIFT & 0xF, MII_CR_100_150MHZ);
}

#[test]
fn interrupt_status_is_cleared_and_a_bus_error_counted() {
    let mut eth = Eth::new(model(), rings(), MAC).unwrap();
    eth.regs_mut()
        .regs
        .insert(STATUS, DMA_RI | DMA_NIS | DMA_FBI | DMA_AIS | (3 << 17));
    let s = eth.take_interrupt();
    assert_eq!(s, DMA_RI | DMA_NIS | DMA_FBI | DMA_AIS);
    assert_eq!(eth.regs_mut().read(STATUS), 3 << 17, "read-only state bits stay");
    assert_eq!(eth.stats().fatal, 1);
}
