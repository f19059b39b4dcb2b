//! The PDO mapping and assignment as the dictionary holds them: the
//! consistency checks of a mapping or assignment write (spec §5), the
//! mapped lengths, the active map.

use super::*;

impl DriveObjects {
    /// Object-specific checks of a write of `v` to entry `e` of `o`, before
    /// the range check: PDO mapping (§5.3), PDO assignment, command
    /// signatures.
    pub(super) fn check_consistency(&self, o: &Object, e: &EntryInfo, v: i64) -> Result<(), SdoAbort> {
        let index = o.info.index;
        if let Some(abort) = crate::stage::window_violation(self, index, v) {
            return Err(abort);
        }
        match (index, o.value) {
            (0x1010, Value::Command) if v != i64::from(SAVE_SIGNATURE) => Err(SdoAbort::TRANSFER),
            (0x1011, Value::Command) if v != i64::from(LOAD_SIGNATURE) => Err(SdoAbort::TRANSFER),
            (0x1600..=0x1603 | 0x1A00..=0x1A03, _) => {
                let rx = index < 0x1A00;
                if e.sub == 0 {
                    // the count is checked against the entries (CiA 301 step d)
                    let n = u8::try_from(v).map_err(|_| SdoAbort::PDO_LENGTH)?;
                    if n > MAPPING_ENTRIES {
                        return Err(SdoAbort::PDO_LENGTH);
                    }
                    let mut bits = 0;
                    for s in 1..=n {
                        bits += self.mapped_bits(self.get(index, s)? as u32, rx)?;
                    }
                    if bits > MAX_PDO_BITS {
                        return Err(SdoAbort::PDO_LENGTH);
                    }
                    Ok(())
                } else if self.get(index, 0)? != 0 {
                    // entries change only while sub 0 = 0 (CiA 301 step b)
                    Err(SdoAbort::DEVICE_STATE)
                } else {
                    self.mapped_bits(v as u32, rx).map(|_| ())
                }
            }
            (0x1C12 | 0x1C13, _) => {
                let pdos = if index == 0x1C12 {
                    0x1600..=0x1603
                } else {
                    0x1A00..=0x1A03
                };
                if e.sub == 0 {
                    if v > 4 {
                        return Err(SdoAbort::VALUE_TOO_HIGH);
                    }
                    for s in 1..=(v as u8) {
                        let pdo = self.get(index, s)?;
                        let twice = (1..s).any(|t| self.get(index, t).ok() == Some(pdo));
                        if !pdos.contains(&pdo) || twice {
                            return Err(SdoAbort::PARAMETER_INCOMPATIBLE);
                        }
                    }
                    Ok(())
                } else if self.get(index, 0)? != 0 {
                    Err(SdoAbort::DEVICE_STATE)
                } else if v != 0 && !pdos.contains(&v) {
                    Err(SdoAbort::PARAMETER_INCOMPATIBLE)
                } else {
                    Ok(())
                }
            }
            _ => Ok(()),
        }
    }

    /// Bits of mapping entry `m` (index << 16 | sub << 8 | bits) in a PDO of
    /// direction `rx`: index 0 is a gap of `bits`; otherwise the entry must
    /// exist, be visible and mappable in that direction (0604 0041h) and
    /// have that bit length (0604 0043h).
    pub(super) fn mapped_bits(&self, m: u32, rx: bool) -> Result<u32, SdoAbort> {
        let (index, sub, bits) = ((m >> 16) as u16, (m >> 8) as u8, m & 0xFF);
        if index == 0 {
            return Ok(bits);
        }
        let e = self
            .locate(index, sub)
            .and_then(Loc::entry)
            .map_err(|_| SdoAbort::NOT_MAPPABLE)?;
        let mappable = if rx {
            e.access.rx_mappable()
        } else {
            e.access.tx_mappable()
        };
        if !mappable {
            Err(SdoAbort::NOT_MAPPABLE)
        } else if u32::from(e.bit_len()) != bits {
            Err(SdoAbort::PARAMETER_INCOMPATIBLE)
        } else {
            Ok(bits)
        }
    }

    /// Puts `layout` into 1600h/1A00h (axis A), as a startup list in Pre-Op
    /// would ([`apply_axis_map`](Self::apply_axis_map) of axis A).
    pub fn apply_map(&mut self, layout: crate::PdoLayout) -> Result<(), SdoAbort> {
        self.apply_axis_map(0, layout)
    }

    /// Puts `layout` on `axis` (0 = A, any other = B) into the axis's channel
    /// (1600h/1A00h + axis), as a startup list in Pre-Op would: sub 0 = 0, the
    /// entries, sub 0 = n (CiA 301 order), through the same checks as a bus
    /// write. Takes effect at the next Pre-Op → Safe-Op.
    pub fn apply_axis_map(&mut self, axis: u16, layout: crate::PdoLayout) -> Result<(), SdoAbort> {
        let axis = u16::from(axis != 0);
        let (rx, tx) = layout.axis_entries(axis);
        for (pdo, entries) in [(0x1600 + axis, rx), (0x1A00 + axis, tx)] {
            self.write(pdo, 0, &[0], CommState::PreOp)?;
            for (sub, e) in (1u8..).zip(entries) {
                self.write(pdo, sub, &e.mapping_value().to_le_bytes(), CommState::PreOp)?;
            }
            let n = u8::try_from(entries.len()).map_err(|_| SdoAbort::PDO_LENGTH)?;
            self.write(pdo, 0, &[n], CommState::PreOp)?;
        }
        Ok(())
    }

    /// The PDOs assigned in `assign` (1C12h or 1C13h), in order.
    pub fn assigned_pdos(&self, assign: u16) -> impl Iterator<Item = u16> + '_ {
        let n = self.get(assign, 0).unwrap_or(0).clamp(0, 4) as u8;
        (1..=n).filter_map(move |s| self.get(assign, s).ok().map(|v| v as u16))
    }

    /// The mapping entries (index << 16 | sub << 8 | bits) of PDO `pdo`.
    pub fn mapping(&self, pdo: u16) -> impl Iterator<Item = u32> + '_ {
        let n = self.get(pdo, 0).unwrap_or(0).clamp(0, i64::from(MAPPING_ENTRIES)) as u8;
        (1..=n).filter_map(move |s| self.get(pdo, s).ok().map(|v| v as u32))
    }

    pub(super) fn sm_bytes(&self, assign: u16) -> usize {
        let bits: u32 = self
            .assigned_pdos(assign)
            .flat_map(|pdo| self.mapping(pdo))
            .map(|m| m & 0xFF)
            .sum();
        (bits as usize).div_ceil(8)
    }

    /// The module ident of `axis` (0 = A, any other = B) as F050h reports it (E-148):
    /// the ident of the ESI module whose PDO configuration axis's channel
    /// (1600h/1A00h + axis) carries now. One of the system modules
    /// ([`crate::module_ident`] of a [`crate::PdoLayout`] on that axis: axis
    /// B's with its objects at +800h/+8000h and its own ident), else a user
    /// module: [`crate::USER_MODULE`] with an FNV-1a hash of the mapping
    /// entries in the low 31 bits, the same for the same configuration; 0
    /// when both PDOs are empty.
    pub fn module_ident(&self, axis: u16) -> u32 {
        let axis = u16::from(axis != 0);
        let (rx, tx) = (0x1600 + axis, 0x1A00 + axis);
        if self.mapping(rx).next().is_none() && self.mapping(tx).next().is_none() {
            return 0;
        }
        for layout in crate::PdoLayout::ALL {
            let (lrx, ltx) = layout.axis_entries(axis);
            let same = |pdo: u16, entries: &[od::PdoEntry]| {
                self.mapping(pdo).eq(entries.iter().map(|e| e.mapping_value()))
            };
            if same(rx, lrx) && same(tx, ltx) {
                return crate::module_ident(layout, axis);
            }
        }
        let mut h: u32 = 0x811C_9DC5;
        for m in self.mapping(rx).chain([0]).chain(self.mapping(tx)) {
            for b in m.to_le_bytes() {
                h = (h ^ u32::from(b)).wrapping_mul(0x0100_0193);
            }
        }
        crate::USER_MODULE | (h & !crate::USER_MODULE)
    }

    /// Puts the axes' [`module_ident`](Self::module_ident) into F050h:01/:02
    /// (the single-axis device's F050h:02 keeps 0: no axis B).
    pub(super) fn refresh_module_idents(&mut self) {
        for axis in (0u16..2).take(self.variant.axes()) {
            let _ = self.set(0xF050, axis as u8 + 1, i64::from(self.module_ident(axis)));
        }
    }
}

/// Whether `index`:`sub` ("EtherCAT Rx SDO Info" numbering) is an integer
/// entry of at most 32 bits that a PDO may map (either direction): what the
/// scope may record ([`crate::scope`]). `Err(0604 0041h)` for anything
/// else (unknown entries included).
pub fn scope_mappable(index: u16, sub: u8) -> Result<DataType, SdoAbort> {
    let e = canonical(index, sub)
        .and_then(|l| l.entry())
        .map_err(|_| SdoAbort::NOT_MAPPABLE)?;
    let mappable = e.access.rx_mappable() || e.access.tx_mappable();
    if mappable && e.data_type.is_integer() && e.data_type.bytes() <= 4 {
        Ok(e.data_type)
    } else {
        Err(SdoAbort::NOT_MAPPABLE)
    }
}
