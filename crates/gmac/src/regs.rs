//! Register offsets and bits of the MAC (XMC4800 reference manual, chapter
//! "Ethernet MAC (ETH)"; the offsets are the `xmc4800` 0.14 PAC's ETH0
//! register block, base 0x5000_C000).

/// ETH0's base address on the XMC4800.
pub const XMC4800_ETH0: usize = 0x5000_C000;

/// MAC configuration.
pub const MAC_CONFIGURATION: u32 = 0x0000;
/// MAC frame filter.
pub const MAC_FRAME_FILTER: u32 = 0x0004;
/// MII (MDIO) address/command.
pub const GMII_ADDRESS: u32 = 0x0010;
/// MII (MDIO) data.
pub const GMII_DATA: u32 = 0x0014;
/// Flow control.
pub const FLOW_CONTROL: u32 = 0x0018;
/// MAC interrupt mask (PMT, timestamp).
pub const INTERRUPT_MASK: u32 = 0x003C;
/// MAC address 0, bytes 4 and 5 (bit 31 reads 1).
pub const MAC_ADDRESS0_HIGH: u32 = 0x0040;
/// MAC address 0, bytes 0…3.
pub const MAC_ADDRESS0_LOW: u32 = 0x0044;
/// MMC receive interrupt mask.
pub const MMC_RECEIVE_INTERRUPT_MASK: u32 = 0x010C;
/// MMC transmit interrupt mask.
pub const MMC_TRANSMIT_INTERRUPT_MASK: u32 = 0x0110;
/// MMC receive checksum offload interrupt mask.
pub const MMC_IPC_RECEIVE_INTERRUPT_MASK: u32 = 0x0200;
/// DMA bus mode.
pub const BUS_MODE: u32 = 0x1000;
/// DMA transmit poll demand (any write).
pub const TRANSMIT_POLL_DEMAND: u32 = 0x1004;
/// DMA receive poll demand (any write).
pub const RECEIVE_POLL_DEMAND: u32 = 0x1008;
/// Start of the receive descriptor list.
pub const RECEIVE_DESCRIPTOR_LIST_ADDRESS: u32 = 0x100C;
/// Start of the transmit descriptor list.
pub const TRANSMIT_DESCRIPTOR_LIST_ADDRESS: u32 = 0x1010;
/// DMA status (write 1 to clear).
pub const STATUS: u32 = 0x1014;
/// DMA operation mode.
pub const OPERATION_MODE: u32 = 0x1018;
/// DMA interrupt enable.
pub const INTERRUPT_ENABLE: u32 = 0x101C;
/// Missed frame and buffer overflow counter (clears on read).
pub const MISSED_FRAME_AND_BUFFER_OVERFLOW_COUNTER: u32 = 0x1020;

/// MAC_CONFIGURATION: receiver enable.
pub const MAC_RE: u32 = 1 << 2;
/// MAC_CONFIGURATION: transmitter enable.
pub const MAC_TE: u32 = 1 << 3;
/// MAC_CONFIGURATION: full duplex.
pub const MAC_DM: u32 = 1 << 11;
/// MAC_CONFIGURATION: 100 Mbit/s (0: 10 Mbit/s).
pub const MAC_FES: u32 = 1 << 14;

/// MAC_FRAME_FILTER: pass all multicast (DCP 01:0E:CF:00:00:00, LLDP
/// 01:80:C2:00:00:0E; the stack filters what it does not serve).
pub const FILTER_PM: u32 = 1 << 4;

/// GMII_ADDRESS: busy.
pub const MII_BUSY: u32 = 1 << 0;
/// GMII_ADDRESS: write (0: read).
pub const MII_WRITE: u32 = 1 << 1;
/// GMII_ADDRESS: CSR clock range field position.
pub const MII_CR_SHIFT: u32 = 2;
/// GMII_ADDRESS: register field position.
pub const MII_MR_SHIFT: u32 = 6;
/// GMII_ADDRESS: PHY address field position.
pub const MII_PA_SHIFT: u32 = 11;
/// CSR clock range for a 100…150 MHz MAC clock: MDC = clock / 62
/// (144 MHz: 2.3 MHz, below IEEE 802.3's 2.5 MHz).
pub const MII_CR_100_150MHZ: u32 = 0b0001;

/// BUS_MODE: software reset (self-clearing).
pub const BUS_SWR: u32 = 1 << 0;
/// BUS_MODE: programmable burst length field position.
pub const BUS_PBL_SHIFT: u32 = 8;
/// BUS_MODE: fixed burst.
pub const BUS_FB: u32 = 1 << 16;
/// BUS_MODE: address-aligned beats.
pub const BUS_AAL: u32 = 1 << 25;

/// OPERATION_MODE: start receive.
pub const OP_SR: u32 = 1 << 1;
/// OPERATION_MODE: operate on second frame.
pub const OP_OSF: u32 = 1 << 2;
/// OPERATION_MODE: start transmit.
pub const OP_ST: u32 = 1 << 13;
/// OPERATION_MODE: flush transmit FIFO (self-clearing).
pub const OP_FTF: u32 = 1 << 20;
/// OPERATION_MODE: transmit store and forward.
pub const OP_TSF: u32 = 1 << 21;
/// OPERATION_MODE: receive store and forward.
pub const OP_RSF: u32 = 1 << 25;

/// STATUS / INTERRUPT_ENABLE: transmit interrupt.
pub const DMA_TI: u32 = 1 << 0;
/// STATUS / INTERRUPT_ENABLE: receive overflow.
pub const DMA_OVF: u32 = 1 << 4;
/// STATUS / INTERRUPT_ENABLE: transmit underflow.
pub const DMA_UNF: u32 = 1 << 5;
/// STATUS / INTERRUPT_ENABLE: receive interrupt.
pub const DMA_RI: u32 = 1 << 6;
/// STATUS / INTERRUPT_ENABLE: receive buffer unavailable.
pub const DMA_RU: u32 = 1 << 7;
/// STATUS / INTERRUPT_ENABLE: fatal bus error.
pub const DMA_FBI: u32 = 1 << 13;
/// STATUS / INTERRUPT_ENABLE: abnormal interrupt summary.
pub const DMA_AIS: u32 = 1 << 15;
/// STATUS / INTERRUPT_ENABLE: normal interrupt summary.
pub const DMA_NIS: u32 = 1 << 16;
/// STATUS: every write-1-to-clear bit (0…16 but the reserved 11 and 12).
pub const DMA_W1C: u32 = 0x0001_E7FF;

/// TDES0 / RDES0: owned by the DMA.
pub const DES0_OWN: u32 = 1 << 31;
/// TDES0: interrupt on completion.
pub const TDES0_IC: u32 = 1 << 30;
/// TDES0: last segment.
pub const TDES0_LS: u32 = 1 << 29;
/// TDES0: first segment.
pub const TDES0_FS: u32 = 1 << 28;
/// TDES0: transmit end of ring.
pub const TDES0_TER: u32 = 1 << 21;
/// TDES0: error summary.
pub const TDES0_ES: u32 = 1 << 15;
/// RDES0: error summary.
pub const RDES0_ES: u32 = 1 << 15;
/// RDES0: first descriptor of a frame.
pub const RDES0_FS: u32 = 1 << 9;
/// RDES0: last descriptor of a frame.
pub const RDES0_LS: u32 = 1 << 8;
/// RDES0: frame length field position (14 bits, CRC included).
pub const RDES0_FL_SHIFT: u32 = 16;
/// RDES0: frame length mask (after the shift).
pub const RDES0_FL_MASK: u32 = 0x3FFF;
/// RDES1: receive end of ring.
pub const RDES1_RER: u32 = 1 << 15;
/// RDES1 / TDES1: buffer 1 size mask (13 bits).
pub const DES1_BS1_MASK: u32 = 0x1FFF;
