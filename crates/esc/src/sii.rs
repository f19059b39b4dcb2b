//! SII EEPROM: the ESC's EEPROM interface registers (0x0500–0x050F) and the
//! layout of the EEPROM content (ETG.1000.6 §5.4, ETG.2010).

/// Bits of the SII control/status register (0x0502, u16).
pub mod control {
    /// ECAT write enable.
    pub const WRITE_ENABLE: u16 = 1 << 0;
    /// EEPROM emulation by the PDI (no real EEPROM).
    pub const EMULATION: u16 = 1 << 5;
    /// Read size: set = 8 bytes per read, clear = 4 bytes.
    pub const READ_8_BYTES: u16 = 1 << 6;
    /// Address algorithm: set = two address bytes (EEPROM > 16 kbit).
    pub const ADDRESS_2_BYTES: u16 = 1 << 7;
    /// Command: read.
    pub const CMD_READ: u16 = 0b001 << 8;
    /// Command: write.
    pub const CMD_WRITE: u16 = 0b010 << 8;
    /// Command: reload the ESC configuration from the EEPROM.
    pub const CMD_RELOAD: u16 = 0b100 << 8;
    /// Command field mask.
    pub const CMD_MASK: u16 = 0b111 << 8;
    /// Checksum error in the ESC configuration area.
    pub const CHECKSUM_ERROR: u16 = 1 << 11;
    /// Device information not loaded (EEPROM loading error).
    pub const LOAD_ERROR: u16 = 1 << 12;
    /// Missing acknowledge or invalid command.
    pub const ACK_ERROR: u16 = 1 << 13;
    /// Write attempted without write enable.
    pub const WRITE_ENABLE_ERROR: u16 = 1 << 14;
    /// Operation in progress.
    pub const BUSY: u16 = 1 << 15;
}

/// Word addresses of the fixed SII header.
pub mod word {
    /// PDI control (loaded into 0x0140).
    pub const PDI_CONTROL: u16 = 0x0000;
    /// PDI configuration (loaded into 0x0150).
    pub const PDI_CONFIG: u16 = 0x0001;
    /// SYNC impulse length in 10 ns (loaded into 0x0982).
    pub const SYNC_IMPULSE_LEN: u16 = 0x0002;
    /// Extended PDI configuration.
    pub const PDI_CONFIG_EXT: u16 = 0x0003;
    /// Configured station alias (loaded into 0x0012).
    pub const STATION_ALIAS: u16 = 0x0004;
    /// Checksum of words 0..6 (low byte).
    pub const CHECKSUM: u16 = 0x0007;
    /// Vendor ID (u32).
    pub const VENDOR_ID: u16 = 0x0008;
    /// Product code (u32).
    pub const PRODUCT_CODE: u16 = 0x000A;
    /// Revision number (u32).
    pub const REVISION: u16 = 0x000C;
    /// Serial number (u32).
    pub const SERIAL: u16 = 0x000E;
    /// Bootstrap receive mailbox offset.
    pub const BOOT_RX_MAILBOX_OFFSET: u16 = 0x0014;
    /// Bootstrap receive mailbox size.
    pub const BOOT_RX_MAILBOX_SIZE: u16 = 0x0015;
    /// Bootstrap send mailbox offset.
    pub const BOOT_TX_MAILBOX_OFFSET: u16 = 0x0016;
    /// Bootstrap send mailbox size.
    pub const BOOT_TX_MAILBOX_SIZE: u16 = 0x0017;
    /// Standard receive mailbox offset (SM0, master → slave).
    pub const STD_RX_MAILBOX_OFFSET: u16 = 0x0018;
    /// Standard receive mailbox size.
    pub const STD_RX_MAILBOX_SIZE: u16 = 0x0019;
    /// Standard send mailbox offset (SM1, slave → master).
    pub const STD_TX_MAILBOX_OFFSET: u16 = 0x001A;
    /// Standard send mailbox size.
    pub const STD_TX_MAILBOX_SIZE: u16 = 0x001B;
    /// Supported mailbox protocols (see [`super::mailbox_protocol`]).
    pub const MAILBOX_PROTOCOL: u16 = 0x001C;
    /// EEPROM size: (size in KiBit) − 1.
    pub const EEPROM_SIZE: u16 = 0x003E;
    /// SII version.
    pub const VERSION: u16 = 0x003F;
    /// First category header.
    pub const FIRST_CATEGORY: u16 = 0x0040;
}

/// Bits of the mailbox-protocol word (0x001C).
pub mod mailbox_protocol {
    /// ADS over EtherCAT.
    pub const AOE: u16 = 1 << 0;
    /// Ethernet over EtherCAT.
    pub const EOE: u16 = 1 << 1;
    /// CAN application protocol over EtherCAT.
    pub const COE: u16 = 1 << 2;
    /// File access over EtherCAT.
    pub const FOE: u16 = 1 << 3;
    /// Servo drive profile over EtherCAT.
    pub const SOE: u16 = 1 << 4;
    /// Vendor specific over EtherCAT.
    pub const VOE: u16 = 1 << 5;
}

/// Category type codes.
pub mod category {
    /// Padding / no operation.
    pub const NOP: u16 = 0;
    /// String repository.
    pub const STRINGS: u16 = 10;
    /// Data types.
    pub const DATA_TYPES: u16 = 20;
    /// General information.
    pub const GENERAL: u16 = 30;
    /// FMMU usage.
    pub const FMMU: u16 = 40;
    /// SyncManager configuration.
    pub const SYNC_MANAGER: u16 = 41;
    /// FMMU extended.
    pub const FMMU_EXT: u16 = 42;
    /// Sync unit.
    pub const SYNC_UNIT: u16 = 43;
    /// TxPDO description.
    pub const TXPDO: u16 = 50;
    /// RxPDO description.
    pub const RXPDO: u16 = 51;
    /// Distributed clock.
    pub const DC: u16 = 60;
    /// End of the category list.
    pub const END: u16 = 0xFFFF;
}

/// CRC-8 of the ESC configuration area (words 0..6, 14 bytes): polynomial
/// x^8 + x^2 + x + 1 (0x07), initial value 0xFF, no reflection, no final XOR.
pub fn config_checksum(bytes: &[u8]) -> u8 {
    let mut crc: u8 = 0xFF;
    for &b in bytes.iter().take(14) {
        crc ^= b;
        for _ in 0..8 {
            crc = if crc & 0x80 != 0 {
                (crc << 1) ^ 0x07
            } else {
                crc << 1
            };
        }
    }
    crc
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn e_sii_checksum_vectors() {
        // Vectors computed with an independent implementation (Python, bit by bit).
        assert_eq!(config_checksum(b"123456789"), 0xFB);
        assert_eq!(
            config_checksum(&[0x80, 0x0C, 0x88, 0x88, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0]),
            0xF2
        );
        assert_eq!(config_checksum(&[0; 14]), 0x30);
        // only the first 14 bytes count
        assert_eq!(config_checksum(&[0; 16]), 0x30);
    }
}
