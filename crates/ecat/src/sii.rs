//! SII EEPROM image (ETG.2010) generated from a [`Device`], and a checked reader
//! for its categories.

use crate::desc::{Device, Pdo};
use esc::sii::{category, config_checksum, mailbox_protocol, word};

/// EEPROM size the image declares (word 0x3E = KiBit − 1).
pub const EEPROM_KBIT: u16 = 32;
/// Bytes of an EEPROM of [`EEPROM_KBIT`].
pub const EEPROM_BYTES: usize = EEPROM_KBIT as usize * 128;
/// PDI control word 0 (low byte 0x80: on-chip bus PDI; ESC config 0).
pub const PDI_CONTROL: u16 = 0x0080;

/// Why an image could not be built.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SiiError {
    /// The output buffer is too small for the image.
    BufferTooSmall,
    /// More than 255 distinct strings, or a string longer than 255 bytes.
    Strings,
    /// A PDO has more than 255 entries.
    TooManyEntries,
}

/// Byte cursor over the output buffer.
struct Writer<'a> {
    buf: &'a mut [u8],
    pos: usize,
}

impl Writer<'_> {
    fn bytes(&mut self, data: &[u8]) -> Result<(), SiiError> {
        let end = self.pos.checked_add(data.len()).ok_or(SiiError::BufferTooSmall)?;
        self.buf
            .get_mut(self.pos..end)
            .ok_or(SiiError::BufferTooSmall)?
            .copy_from_slice(data);
        self.pos = end;
        Ok(())
    }
    fn u8(&mut self, v: u8) -> Result<(), SiiError> {
        self.bytes(&[v])
    }
    fn u16(&mut self, v: u16) -> Result<(), SiiError> {
        self.bytes(&v.to_le_bytes())
    }
    fn u32(&mut self, v: u32) -> Result<(), SiiError> {
        self.bytes(&v.to_le_bytes())
    }
    fn zeros(&mut self, n: usize) -> Result<(), SiiError> {
        for _ in 0..n {
            self.u8(0)?;
        }
        Ok(())
    }
    /// Writes u16 `v` at an earlier position.
    fn patch_u16(&mut self, at: usize, v: u16) -> Result<(), SiiError> {
        let [lo, hi] = v.to_le_bytes();
        match self.buf.get_mut(at..at + 2) {
            Some([a, b]) => {
                *a = lo;
                *b = hi;
                Ok(())
            }
            _ => Err(SiiError::BufferTooSmall),
        }
    }
    /// Runs `body` as a category of type `kind`: header, data, pad to a word, size.
    fn category(
        &mut self,
        kind: u16,
        body: impl FnOnce(&mut Self) -> Result<(), SiiError>,
    ) -> Result<(), SiiError> {
        self.u16(kind)?;
        let size_at = self.pos;
        self.u16(0)?;
        let start = self.pos;
        body(self)?;
        if (self.pos - start) % 2 != 0 {
            self.u8(0)?;
        }
        let words = u16::try_from((self.pos - start) / 2).map_err(|_| SiiError::BufferTooSmall)?;
        self.patch_u16(size_at, words)
    }
}

/// The string repository: distinct strings, 1-based indices (0 = no string).
struct Strings {
    list: heapless::Vec<&'static str, 255>,
}

impl Strings {
    fn add(&mut self, s: &'static str) -> Result<(), SiiError> {
        if s.is_empty() || self.list.contains(&s) {
            return Ok(());
        }
        if s.len() > 255 {
            return Err(SiiError::Strings);
        }
        self.list.push(s).map_err(|_| SiiError::Strings)
    }
    fn idx(&self, s: &str) -> u8 {
        self.list
            .iter()
            .position(|&x| x == s)
            .and_then(|i| u8::try_from(i + 1).ok())
            .unwrap_or(0)
    }
}

/// Builds the SII EEPROM image of `desc` into `out`; returns the bytes used
/// (up to and including the END marker). The rest of `out` is filled with 0xFF
/// (erased EEPROM).
pub fn build_sii(desc: &Device, out: &mut [u8]) -> Result<usize, SiiError> {
    let mut strings = Strings {
        list: heapless::Vec::new(),
    };
    // string 1 is the device's type (the ESI's `Type`, the order code), as
    // in vendor SIIs: SOEM and other tools name a slave after string 1
    for s in [desc.order_code, desc.name, desc.group] {
        strings.add(s)?;
    }
    for pdo in desc.rx_pdos.iter().chain(desc.tx_pdos) {
        strings.add(pdo.name)?;
        for e in pdo.entries {
            strings.add(e.name)?;
        }
    }
    for m in desc.dc_modes {
        strings.add(m.name)?;
        strings.add(m.description)?;
    }

    out.fill(0xFF);
    let mut w = Writer { buf: out, pos: 0 };
    // Words 0..0x3F: ESC configuration area, identity, mailbox, size, version.
    w.zeros(usize::from(word::FIRST_CATEGORY) * 2)?;
    let put16 = |w: &mut Writer, word: u16, v: u16| w.patch_u16(usize::from(word) * 2, v);
    let put32 = |w: &mut Writer, word: u16, v: u32| {
        put16(w, word, v as u16)?;
        put16(w, word + 1, (v >> 16) as u16)
    };
    put16(&mut w, word::PDI_CONTROL, PDI_CONTROL)?;
    let mut head = [0u8; 14];
    head.copy_from_slice(w.buf.get(0..14).ok_or(SiiError::BufferTooSmall)?);
    put16(&mut w, word::CHECKSUM, u16::from(config_checksum(&head)))?;
    let id = &desc.identity;
    put32(&mut w, word::VENDOR_ID, id.vendor_id)?;
    put32(&mut w, word::PRODUCT_CODE, id.product_code)?;
    put32(&mut w, word::REVISION, id.revision)?;
    put32(&mut w, word::SERIAL, id.serial)?;
    let (rx, tx) = (desc.mailbox_out, desc.mailbox_in);
    for base in [word::BOOT_RX_MAILBOX_OFFSET, word::STD_RX_MAILBOX_OFFSET] {
        put16(&mut w, base, rx.start)?;
        put16(&mut w, base + 1, rx.length)?;
        put16(&mut w, base + 2, tx.start)?;
        put16(&mut w, base + 3, tx.length)?;
    }
    put16(&mut w, word::MAILBOX_PROTOCOL, desc.mailbox_protocols)?;
    put16(&mut w, word::EEPROM_SIZE, EEPROM_KBIT - 1)?;
    put16(&mut w, word::VERSION, 1)?;

    w.category(category::STRINGS, |w| {
        w.u8(strings.list.len() as u8)?;
        for s in &strings.list {
            w.u8(s.len() as u8)?;
            w.bytes(s.as_bytes())?;
        }
        Ok(())
    })?;

    w.category(category::GENERAL, |w| {
        let group = strings.idx(desc.group);
        w.bytes(&[group, 0, strings.idx(desc.order_code), strings.idx(desc.name), 0])?;
        w.u8(desc.coe_details)?;
        // FoE details: 1 = FoE supported (the firmware download, issue 8)
        w.u8(u8::from(desc.mailbox_protocols & mailbox_protocol::FOE != 0))?;
        let eoe = desc.mailbox_protocols & mailbox_protocol::EOE != 0;
        w.u8(u8::from(eoe))?;
        w.bytes(&[0, 0, 0, 0])?; // SoE channels, DS402 channels, SysmanClass, flags
        w.u16(0)?; // current on EBus (mA)
        w.bytes(&[group, 0])?;
        let mut ports = 0u16;
        for p in 0..desc.ports.min(4) {
            ports |= 1 << (4 * p);
        }
        w.u16(ports)?;
        w.u16(0)?; // physical memory address
        w.zeros(12)
    })?;

    w.category(category::FMMU, |w| {
        for f in desc.fmmus {
            w.u8(f.code())?;
        }
        Ok(())
    })?;

    w.category(category::SYNC_MANAGER, |w| {
        for (start, len, control, kind) in [
            (rx.start, rx.length, rx.control, 1),
            (tx.start, tx.length, tx.control, 2),
            (desc.outputs.start, 0, desc.outputs.control, 3),
            (desc.inputs.start, 0, desc.inputs.control, 4),
        ] {
            w.u16(start)?;
            w.u16(len)?;
            w.bytes(&[control, 0, 1, kind])?;
        }
        Ok(())
    })?;

    let pdos = |w: &mut Writer, list: &[Pdo], assigned: &[u16], sm: u8| {
        for pdo in list {
            let n = u8::try_from(pdo.entries.len()).map_err(|_| SiiError::TooManyEntries)?;
            w.u16(pdo.index)?;
            w.u8(n)?;
            // 0xFF: not assigned to a SyncManager by default.
            w.u8(if assigned.contains(&pdo.index) { sm } else { 0xFF })?;
            w.u8(0)?; // DC sync
            w.u8(strings.idx(pdo.name))?;
            w.u16(0)?; // flags
            for e in pdo.entries {
                w.u16(e.index)?;
                w.u8(e.sub)?;
                w.u8(strings.idx(e.name))?;
                w.u8(e.data_type.code() as u8)?;
                w.u8(e.bits())?;
                w.u16(0)?;
            }
        }
        Ok(())
    };
    if !desc.tx_pdos.is_empty() {
        w.category(category::TXPDO, |w| pdos(w, desc.tx_pdos, desc.tx_assign, 3))?;
    }
    if !desc.rx_pdos.is_empty() {
        w.category(category::RXPDO, |w| pdos(w, desc.rx_pdos, desc.rx_assign, 2))?;
    }

    if desc.dc_supported() {
        w.category(category::DC, |w| {
            for m in desc.dc_modes {
                w.u32(m.cycle_time_ns)?;
                w.u32(m.shift_ns)?;
                w.u32(0)?; // shift 1
                w.u16(0)?; // SYNC1 cycle factor
                w.u16(m.assign_activate)?;
                w.u16(m.sync0_cycle_factor as u16)?;
                w.u8(strings.idx(m.name))?;
                w.u8(strings.idx(m.description))?;
                w.zeros(4)?;
            }
            Ok(())
        })?;
    }

    w.u16(category::END)?;
    w.u16(0xFFFF)?;
    Ok(w.pos)
}

/// Word `n` of an SII image.
pub fn sii_word(image: &[u8], n: u16) -> Option<u16> {
    let at = usize::from(n) * 2;
    match image.get(at..at + 2) {
        Some(&[lo, hi]) => Some(u16::from_le_bytes([lo, hi])),
        _ => None,
    }
}

/// A category of an SII image.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Category<'a> {
    /// Category type (`esc::sii::category`).
    pub kind: u16,
    /// Category data (size words × 2 bytes).
    pub data: &'a [u8],
}

/// Checked iterator over the categories of an SII image; ends at END or at
/// the first category that does not fit the image.
#[derive(Debug, Clone)]
pub struct Categories<'a> {
    image: &'a [u8],
    pos: usize,
}

/// The categories of `image`, starting at word 0x40.
pub fn categories(image: &[u8]) -> Categories<'_> {
    Categories {
        image,
        pos: usize::from(word::FIRST_CATEGORY) * 2,
    }
}

impl<'a> Iterator for Categories<'a> {
    type Item = Category<'a>;

    fn next(&mut self) -> Option<Category<'a>> {
        let head = self.image.get(self.pos..self.pos.checked_add(4)?)?;
        let (kind, words) = match head {
            &[a, b, c, d] => (u16::from_le_bytes([a, b]), u16::from_le_bytes([c, d])),
            _ => return None,
        };
        if kind == category::END {
            return None;
        }
        let start = self.pos + 4;
        let end = start.checked_add(usize::from(words) * 2)?;
        let data = self.image.get(start..end)?;
        self.pos = end;
        Some(Category { kind, data })
    }
}

/// The data of the first category of type `kind`.
pub fn find_category(image: &[u8], kind: u16) -> Option<&[u8]> {
    categories(image).find(|c| c.kind == kind).map(|c| c.data)
}

/// String `idx` (1-based) of a STRINGS category's data.
pub fn sii_string(strings: &[u8], idx: u8) -> Option<&[u8]> {
    let count = *strings.first()?;
    if idx == 0 || idx > count {
        return None;
    }
    let mut pos = 1usize;
    for i in 1..=idx {
        let len = usize::from(*strings.get(pos)?);
        let s = strings.get(pos + 1..pos + 1 + len)?;
        if i == idx {
            return Some(s);
        }
        pos += 1 + len;
    }
    None
}

/// Iterator over the fixed-size records of a category (`len` bytes each).
pub fn records(data: &[u8], len: usize) -> impl Iterator<Item = &[u8]> {
    data.chunks_exact(len.max(1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::desc::*;

    static ENTRIES: [PdoEntry; 2] = [
        PdoEntry::new(0x6040, 0, DataType::U16, "Controlword"),
        PdoEntry::new(0x6060, 0, DataType::I8, "Mode"),
    ];
    static RX: [Pdo; 1] = [Pdo {
        index: 0x1600,
        name: "Out",
        entries: &ENTRIES,
    }];
    /// The crate's test device with another identity, names and PDOs.
    static DEV: Device = Device {
        identity: Identity {
            vendor_id: 0xB9,
            product_code: 0x1234_5678,
            revision: 7,
            serial: 9,
        },
        name: "Dev",
        order_code: "ORD",
        mailbox_protocols: mailbox_protocol::COE,
        process_ram_end: 0x2000,
        rx_pdos: &RX,
        tx_pdos: &[],
        rx_assign: &[0x1600],
        tx_assign: &[],
        ..crate::tests::DEV_DESC
    };

    #[test]
    fn e005_sii_header_checksum_and_identity() {
        let mut img = [0u8; 1024];
        let n = build_sii(&DEV, &mut img).unwrap();
        assert_eq!(n % 2, 0);
        assert_eq!(sii_word(&img, 0), Some(0x0080));
        assert_eq!(sii_word(&img, 7), Some(u16::from(config_checksum(&img[..14]))));
        assert_eq!(sii_word(&img, 8), Some(0xB9));
        assert_eq!(sii_word(&img, 0xA), Some(0x5678));
        assert_eq!(sii_word(&img, 0xB), Some(0x1234));
        assert_eq!(sii_word(&img, 0xC), Some(7));
        assert_eq!(sii_word(&img, 0xE), Some(9));
        assert_eq!(sii_word(&img, 0x3E), Some(31));
        assert_eq!(img[n], 0xFF);
        assert_eq!(&img[n - 4..n - 2], &[0xFF, 0xFF]);
    }

    #[test]
    fn sii_categories_parse_back() {
        let mut img = [0u8; 1024];
        build_sii(&DEV, &mut img).unwrap();
        let kinds: heapless::Vec<u16, 16> = categories(&img).map(|c| c.kind).collect();
        assert_eq!(
            kinds.as_slice(),
            &[
                category::STRINGS,
                category::GENERAL,
                category::FMMU,
                category::SYNC_MANAGER,
                category::RXPDO
            ]
        );
        let strings = find_category(&img, category::STRINGS).unwrap();
        let general = find_category(&img, category::GENERAL).unwrap();
        assert_eq!(general.len(), 32);
        assert_eq!(sii_string(strings, general[3]), Some(&b"Dev"[..]));
        assert_eq!(sii_string(strings, general[0]), Some(&b"Drives"[..]));
        assert_eq!(sii_string(strings, general[2]), Some(&b"ORD"[..]));
        assert_eq!(u16::from_le_bytes([general[16], general[17]]), 0x0011);
        // odd FMMU count padded to a word
        assert_eq!(find_category(&img, category::FMMU), Some(&[1, 2, 3, 0][..]));
        let rx = find_category(&img, category::RXPDO).unwrap();
        assert_eq!(rx.len(), 8 + 2 * 8);
        assert_eq!(&rx[..4], &[0x00, 0x16, 2, 2]);
        assert_eq!(rx[8 + 8 + 5], 8); // second entry: 8 bits
        assert_eq!(sii_string(strings, rx[8 + 3]), Some(&b"Controlword"[..]));
    }

    #[test]
    fn sii_buffer_too_small_is_an_error() {
        let mut img = [0u8; 200];
        assert_eq!(build_sii(&DEV, &mut img), Err(SiiError::BufferTooSmall));
        let mut img = [0u8; 10];
        assert_eq!(build_sii(&DEV, &mut img), Err(SiiError::BufferTooSmall));
    }

    #[test]
    fn sii_reader_stops_on_truncated_category() {
        let mut img = [0u8; 1024];
        let n = build_sii(&DEV, &mut img).unwrap();
        // a STRINGS header claiming more words than the image holds
        img[0x80..0x84].copy_from_slice(&[10, 0, 0xFF, 0x7F]);
        assert_eq!(categories(&img[..n]).count(), 0);
        assert_eq!(sii_string(&[2, 1, b'a'], 2), None);
    }
}
