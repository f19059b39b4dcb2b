//! SII EEPROM interface (0x0500–0x050F) and the power-on load of the ESC
//! configuration area.

use ::esc::{regs, sii, sii::control};

use super::{dl, Esc, SiiPending, SII_MAX_BYTES};

/// Words in the SII image.
const SII_WORDS: u32 = (SII_MAX_BYTES / 2) as u32;

impl Esc {
    /// A word of the SII image.
    fn sii_word(&self, w: usize) -> u16 {
        match self.sii.get(2 * w..2 * w + 2) {
            Some(&[lo, hi]) => u16::from_le_bytes([lo, hi]),
            _ => 0xFFFF,
        }
    }

    /// Loads alias, PDI control, ESC configuration, PDI configuration and the
    /// SYNC pulse length from the image and checks the configuration checksum
    /// (power on and the reload command).
    pub(super) fn load_sii_config(&mut self) {
        let w0 = self.sii_word(sii::word::PDI_CONTROL.into());
        self.set_u8(regs::PDI_CONTROL, w0 as u8);
        self.set_u8(regs::ESC_CONFIG, (w0 >> 8) as u8);
        let w1 = self.sii_word(sii::word::PDI_CONFIG.into());
        self.set_u16(regs::PDI_CONFIG, w1);
        let w2 = self.sii_word(sii::word::SYNC_IMPULSE_LEN.into());
        self.set_u16(regs::dc::PULSE_LENGTH, w2);
        let w4 = self.sii_word(sii::word::STATION_ALIAS.into());
        self.set_u16(regs::STATION_ALIAS, w4);
        let ok = self
            .sii
            .get(..14)
            .map(sii::config_checksum)
            .zip(self.sii.get(14).copied())
            .is_some_and(|(crc, stored)| crc == stored);
        let mut c = (self.get_u16(regs::SII_CONTROL) & !control::CHECKSUM_ERROR) | control::READ_8_BYTES;
        if !ok {
            c |= control::CHECKSUM_ERROR;
        }
        self.set_u16(regs::SII_CONTROL, c);
        let mut s = self.get_u16(regs::DL_STATUS) & !dl::PDI_OPERATIONAL;
        if ok {
            s |= dl::PDI_OPERATIONAL;
        }
        self.set_u16(regs::DL_STATUS, s);
    }

    /// ECAT wrote the command byte of 0x0502 (`value` = the written u16; the
    /// low byte is 0 when the write did not cover it). Ignored while busy.
    pub(super) fn sii_command_written(&mut self, value: u16) {
        if self.sii_pending.is_some() {
            return;
        }
        let mut c = self.get_u16(regs::SII_CONTROL)
            & !(control::ACK_ERROR | control::WRITE_ENABLE_ERROR | control::CMD_MASK | control::BUSY);
        let cmd = value & control::CMD_MASK;
        match cmd {
            0 => {}
            control::CMD_READ | control::CMD_RELOAD => {}
            control::CMD_WRITE if value & control::WRITE_ENABLE == 0 => {
                c |= control::WRITE_ENABLE_ERROR;
            }
            control::CMD_WRITE => {}
            _ => c |= control::ACK_ERROR,
        }
        let valid = matches!(cmd, control::CMD_READ | control::CMD_RELOAD | control::CMD_WRITE)
            && c & control::WRITE_ENABLE_ERROR == 0;
        if !valid {
            self.set_u16(regs::SII_CONTROL, c);
            return;
        }
        if self.config.sii_busy.is_zero() {
            self.set_u16(regs::SII_CONTROL, c);
            self.sii_execute(cmd);
        } else {
            self.set_u16(regs::SII_CONTROL, c | control::BUSY | cmd);
            self.sii_pending = Some(SiiPending {
                command: cmd,
                done_at: self.now.saturating_add(self.config.sii_busy),
            });
        }
    }

    /// Executes an SII command and clears BUSY.
    pub(super) fn sii_execute(&mut self, cmd: u16) {
        let c = self.get_u16(regs::SII_CONTROL) & !(control::BUSY | control::CMD_MASK);
        self.set_u16(regs::SII_CONTROL, c);
        let word = self.get_u32(regs::SII_ADDRESS);
        let in_range = word < SII_WORDS;
        let base = (word as usize).saturating_mul(2);
        match cmd {
            control::CMD_READ if in_range => {
                let mut data = [0xFFu8; 8];
                for (k, d) in data.iter_mut().enumerate() {
                    if let Some(b) = self.sii.get(base + k) {
                        *d = *b;
                    }
                }
                self.set_bytes(regs::SII_DATA, &data);
            }
            control::CMD_WRITE if in_range => {
                let mut w = [0u8; 2];
                self.get_bytes(regs::SII_DATA, &mut w);
                if let Some(dst) = self.sii.get_mut(base..base + 2) {
                    dst.copy_from_slice(&w);
                }
            }
            control::CMD_RELOAD => self.load_sii_config(),
            _ => self.set_u16(regs::SII_CONTROL, c | control::ACK_ERROR),
        }
    }
}
