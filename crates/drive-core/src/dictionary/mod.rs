//! [`DriveObjects`]: the values of the declaration in [`crate::objects`] and
//! the CoE access rules (spec §6.5 abort codes, §5 PDO mapping/assignment,
//! §2.4 visibility, §2.5 save/restore).
//!
//! Subindex numbering: the bus side ([`od::Dictionary`]) uses the active
//! [`Template`]; the runtime side ([`DriveObjects::get`], [`DriveObjects::set`],
//! [`LiveValues`]) always uses the "EtherCAT Rx SDO Info" numbering
//! (element + 1 for manufacturer arrays), so it does not change with the
//! template.

use core::cell::Cell;
use core::marker::PhantomData;
use core::sync::atomic::{AtomicU32, Ordering};

use crate::objects::{self, enumeration, find, Object, Value, IMAGE_BYTES, OBJECTS, OFFSETS};
use crate::pdo_image::{CopyOp, WIDTH_SHIFT};
use crate::{parameter_index, Variant, MAPPING_ENTRIES, SOFTWARE_BUILD};
use od::{CommState, DataType, Dictionary, EntryInfo, ObjectInfo, SdoAbort};

mod mapping;
mod persist;
mod prepared;
mod records;
mod resolve;
mod scaling;
mod slot;
mod standard;

pub use mapping::scope_mappable;
pub use persist::{ImageError, PERSISTENT_IMAGE_BYTES};
pub use prepared::Prepared;
use resolve::*;
pub use slot::Slot;
#[cfg(test)]
pub(crate) use slot::SlotValue;
pub(crate) use slot::Typed;
use slot::*;
pub use slot::{read_slot, write_slot};

/// Signature written to 1010h:01 to save ("save", CiA 301).
pub const SAVE_SIGNATURE: u32 = 0x6576_6173;
/// Signature written to 1011h:01 to restore defaults ("load", CiA 301).
pub const LOAD_SIGNATURE: u32 = 0x6461_6F6C;
/// Longest PDO in bits: 24 entries of 32 bits (spec §5.3, inference).
pub const MAX_PDO_BITS: u32 = MAPPING_ENTRIES as u32 * 32;

/// The subindex template of manufacturer arrays and records (spec §2.6).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Template {
    /// "EtherCAT Rx": subindex = element number; no SDO Info.
    Rx,
    /// "EtherCAT Rx SDO Info": subindex = element number + 1 (default).
    SdoInfo,
}

/// Revision number 1018h:03 in `template` (E-008): the software build
/// number shifted left by one, bit 0 = 1 for "EtherCAT Rx SDO Info".
/// [`SOFTWARE_BUILD`] is the revision of the default template.
pub const fn revision(template: Template) -> u32 {
    (SOFTWARE_BUILD & !1)
        | match template {
            Template::Rx => 0,
            Template::SdoInfo => 1,
        }
}
const _: () = assert!(
    SOFTWARE_BUILD & 1 == 1,
    "SOFTWARE_BUILD is the SDO-Info template revision"
);

/// Requests for the runtime, set by bus writes, cleared by
/// [`DriveObjects::take_requests`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Requests {
    /// Save the persistent values ([`DriveObjects::persistent_image`]):
    /// 1010h:01 = "save" or A00\[0\] = 1.
    pub save: bool,
    /// Restart the device: A09\[0\] = 1.
    pub restart: bool,
    /// 1011h:01 = "load" restored the defaults in RAM (the stored image is
    /// unchanged until the next save).
    pub defaults_restored: bool,
}

/// Values owned by other parts of the firmware ([`Value::Live`] objects):
/// the statusword, actual values, error register, diagnosis history, ESM
/// state… A provider answers what it owns and returns `None` for the rest,
/// which the dictionary then answers from its RAM image (where the runtime
/// may also push values with [`DriveObjects::set`]). Indices and subindices
/// use the "EtherCAT Rx SDO Info" numbering.
pub trait LiveValues {
    /// Reads `index`:`sub` into `buf`: `Some(byte count or abort)` if owned.
    fn read(&mut self, index: u16, sub: u8, buf: &mut [u8]) -> Option<Result<usize, SdoAbort>> {
        let _ = (index, sub, buf);
        None
    }

    /// A checked write (access, size, range) to a live entry, before the
    /// dictionary stores it in its RAM image; an error refuses the write.
    fn write(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), SdoAbort> {
        let _ = (index, sub, data);
        Ok(())
    }

    /// A checked write (access, size, range, value list) to an entry only
    /// the provider keeps ([`Value::Provided`]): the provider takes it or
    /// refuses it; one it does not own answers 0800 0022h.
    fn provide(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), SdoAbort> {
        let _ = (index, sub, data);
        Err(SdoAbort::DEVICE_STATE)
    }
}

/// No live-value provider: live entries answer from the RAM image.
#[derive(Debug, Default, Clone, Copy)]
pub struct NoLive;
impl LiveValues for NoLive {}

/// The drive's object dictionary: the RAM image of every value, the active
/// template and the requests for the runtime. Implements [`od::Dictionary`]
/// (live entries from the RAM image; see [`DriveObjects::with_live`]).
///
/// [`get`](Self::get)/[`set`](Self::set) resolve `index`:`sub` through a
/// shared cache (open addressing, filled on first use): a hash, a compare
/// and a load instead of a binary search, an entry scan and an offset sum.
/// The entries the control cycle and the process-data copy touch every
/// cycle are resolved once into a [`Slot`] and then read and written with
/// [`load_slot`](Self::load_slot)/[`store_slot`](Self::store_slot) and their
/// typed forms (docs/architecture.md, cycle cost).
///
/// (`repr(C)`: the RAM image first, at the struct's address, so the control
/// cycle's loads and stores at a slot's offset need no extra add.)
#[derive(Debug, Clone)]
#[repr(C)]
pub struct DriveObjects {
    image: [u8; IMAGE_BYTES],
    template: Template,
    requests: Requests,
    /// Counts configuration changes ([`Self::config_generation`]).
    config_generation: u32,
    /// Counts the configuration changes each axis reads
    /// ([`Self::axis_config_generation`]).
    axis_generation: [u32; 2],
    /// The SyncManager lengths of the mapping (RxPDO, TxPDO bytes) with the
    /// configuration generation they were summed at: the slave asks every
    /// poll, the mapping changes only with the generation.
    pdo_bytes: Cell<Option<(u32, (usize, usize))>>,
    /// J401\[5\] of each axis as last synchronised with \[3\] (`records.rs`).
    all_accelerations: [u32; 2],
    /// The device the dictionary describes (fixed at construction).
    variant: Variant,
}

/// Equal dictionaries hold the same values and template; how they got
/// there (the configuration generation) does not count.
impl PartialEq for DriveObjects {
    fn eq(&self, other: &Self) -> bool {
        self.image == other.image
            && self.template == other.template
            && self.requests == other.requests
            && self.variant == other.variant
    }
}

impl Eq for DriveObjects {}

impl Default for DriveObjects {
    fn default() -> Self {
        Self::new()
    }
}

/// [`DriveObjects`] with a [`LiveValues`] provider, as a fieldbus sees it:
/// from [`DriveObjects::with_live`] the values as the dictionary keeps them,
/// from [`DriveObjects::parameter_channel`] the A213-scaled entries in the
/// parameter channel's representation (A213\[1\], `scaling.rs`).
#[derive(Debug)]
pub struct WithLive<'a, L: LiveValues + ?Sized> {
    /// The dictionary.
    pub objects: &'a mut DriveObjects,
    /// The provider of live values.
    pub live: &'a mut L,
    /// Reads and writes convert the A213-scaled entries (parameter channel).
    channel: bool,
}

impl DriveObjects {
    /// The double-axis device's dictionary ([`Variant::Double`]): every
    /// value at its default, template "EtherCAT Rx SDO Info".
    #[inline(always)]
    pub fn new() -> Self {
        Self::for_variant(Variant::Double)
    }

    /// The dictionary of `variant`: every value at its default, template
    /// "EtherCAT Rx SDO Info". The single-axis device's has no axis-B
    /// objects (0602 0000h, not in SDO Info, not mappable) and its own
    /// declaration of a few objects ([`crate::objects::single`]).
    #[inline(always)]
    pub fn for_variant(variant: Variant) -> Self {
        let mut objects = Self {
            image: [0; IMAGE_BYTES],
            template: Template::SdoInfo,
            requests: Requests {
                save: false,
                restart: false,
                defaults_restored: false,
            },
            config_generation: 0,
            axis_generation: [0; 2],
            pdo_bytes: Cell::new(None),
            all_accelerations: [records::ALL_ACCELERATIONS_DEFAULT; 2],
            variant,
        };
        persist::write_defaults(&mut objects.image, |_, _| true);
        objects.write_variant_defaults(|_| true);
        objects.refresh_module_idents();
        objects
    }

    /// The device this dictionary describes.
    pub fn variant(&self) -> Variant {
        self.variant
    }

    /// The object at `index` as this device declares it
    /// ([`Variant::declared`]), whether the bus sees it or not; `None` when
    /// the declaration has no such index.
    pub fn declared_object(&self, index: u16) -> Option<&'static Object> {
        find(index).map(|(_, o)| self.variant.declared(o))
    }

    /// A counter that changes whenever a configuration value may have
    /// changed: a changed RAM value other than a cyclic set-point (6040h,
    /// 6060h, 607Ah, 60C1h, 60FFh, 6071h, 60B1h, 60B2h, 6042h, 60B8h, I210 of
    /// either axis), a load, a restore or a template switch. Live values never
    /// change it. The axes re-read their configuration only when it moved.
    pub fn config_generation(&self) -> u32 {
        self.config_generation
    }

    /// The configuration generation of axis `axis` (0 = A, 1 = B): as
    /// [`config_generation`](Self::config_generation), but a changed value
    /// of the other axis' own objects (CiA 402 objects at 6000h…67FFh for
    /// axis A, 6800h…6FFFh and the manufacturer window from A000h for axis
    /// B) leaves it (issue 36: a telegram's ramp write on axis A does not
    /// make axis B read its snapshot again). Changes whose entry is not
    /// known here (a slot store, a load, a template switch) move both.
    #[inline(always)]
    pub fn axis_config_generation(&self, axis: usize) -> u32 {
        let [a, b] = self.axis_generation;
        if axis == 0 {
            a
        } else {
            b
        }
    }

    fn config_changed(&mut self) {
        self.config_generation = self.config_generation.wrapping_add(1);
        let [a, b] = self.axis_generation;
        self.axis_generation = [a.wrapping_add(1), b.wrapping_add(1)];
    }

    /// A configuration change of entry `index` (the dictionary's numbering):
    /// the axes whose objects it can be.
    fn config_changed_at(&mut self, index: u16) {
        self.config_generation = self.config_generation.wrapping_add(1);
        let (to_a, to_b) = match index {
            0x6000..=0x67FF => (1, 0),
            0x6800..=0x6FFF | 0xA000..=0xFFFF => (0, 1),
            _ => (1, 1),
        };
        let [a, b] = self.axis_generation;
        self.axis_generation = [a.wrapping_add(to_a), b.wrapping_add(to_b)];
    }

    /// This dictionary with `live` answering the live entries; values as
    /// the dictionary keeps them (the A213-scaled entries in the process
    /// data's representation, A213\[0\]).
    pub fn with_live<'a, L: LiveValues + ?Sized>(&'a mut self, live: &'a mut L) -> WithLive<'a, L> {
        WithLive {
            objects: self,
            live,
            channel: false,
        }
    }

    /// This dictionary as a fieldbus's parameter channel sees it (CoE SDO
    /// and the UDP parameter service of the EtherCAT drive): `live` answers
    /// the live entries, and the entries fieldbus scaling acts on read and
    /// write in the representation of A213\[1\] (E-143, E-086;
    /// [`DriveObjects::channel_shift`]). With A213\[1\] = A213\[0\] (both
    /// native by default) the same as [`with_live`](Self::with_live).
    pub fn parameter_channel<'a, L: LiveValues + ?Sized>(&'a mut self, live: &'a mut L) -> WithLive<'a, L> {
        WithLive {
            objects: self,
            live,
            channel: true,
        }
    }

    /// The active subindex template.
    pub fn template(&self) -> Template {
        self.template
    }

    /// Switches the subindex template (a configuration setting of the
    /// device; it changes 1018h:03, the addressing of manufacturer arrays and
    /// the availability of SDO Info at once; the SII/ESI must follow).
    pub fn set_template(&mut self, template: Template) {
        self.template = template;
        self.config_changed();
    }

    /// The requests set since the last call, cleared.
    pub fn take_requests(&mut self) -> Requests {
        core::mem::take(&mut self.requests)
    }

    /// Requests a save (as A00\[0\] = 1 does).
    pub fn request_save(&mut self) {
        self.requests.save = true;
    }

    /// Requests a restart (as A09\[0\] = 1 does).
    pub fn request_restart(&mut self) {
        self.requests.restart = true;
    }

    /// The requests set since the last [`take_requests`](Self::take_requests).
    pub fn requests(&self) -> Requests {
        self.requests
    }

    /// The access level of CoE accesses, A10\[2\] (E-017).
    pub fn access_level(&self) -> u8 {
        self.get(parameter_index(0, 10), 3).map_or(0, |v| v as u8)
    }

    /// Seen on the bus: an object of this device (the single-axis device
    /// has no axis-B objects) within the access level.
    fn visible(&self, o: &Object) -> bool {
        self.variant.has_object(o.info.index) && o.level <= self.access_level()
    }

    fn sdo_info(&self) -> bool {
        self.template == Template::SdoInfo
    }

    /// The visible entry `index`:`sub` in the active template.
    fn locate(&self, index: u16, sub: u8) -> Result<Loc, SdoAbort> {
        let (obj, o) = find(index).ok_or(SdoAbort::NO_OBJECT)?;
        if !self.visible(o) {
            return Err(SdoAbort::NO_OBJECT);
        }
        let rx_view = !self.sdo_info() && o.has_rx_view();
        let view = o.view(self.sdo_info());
        let p = view.entries.position(sub).ok_or(SdoAbort::NO_SUBINDEX)?;
        Ok(Loc {
            obj,
            pos: if rx_view { p + 1 } else { p },
        })
    }

    fn ram(&self, loc: Loc) -> Result<&[u8], SdoAbort> {
        self.image.get(loc.slot()?).ok_or(SdoAbort::GENERAL)
    }

    /// The value of a target entry (after [`follow`]) from RAM or the
    /// declaration (this device's: [`Variant::declared`]).
    fn read_loc(&self, loc: Loc, buf: &mut [u8]) -> Result<usize, SdoAbort> {
        let o = self.variant.declared(loc.object()?);
        let e = o.info.entries.get(loc.pos).ok_or(SdoAbort::NO_SUBINDEX)?;
        match o.value {
            Value::Ram | Value::Live => {
                let raw = self.ram(loc)?;
                let len = match e.data_type {
                    DataType::VisibleString(_) => raw.iter().position(|&b| b == 0).unwrap_or(raw.len()),
                    _ => raw.len(),
                };
                put(buf, raw.get(..len).ok_or(SdoAbort::GENERAL)?)
            }
            Value::Text(s) => put(buf, s.as_bytes()),
            // only a provider has these (`read_with` asked it)
            Value::Provided => Err(SdoAbort::DEVICE_STATE),
            Value::Identity if e.sub == 3 => e.data_type.encode(i64::from(revision(self.template)), buf),
            _ if e.data_type.is_string() => Ok(0),
            _ => e.data_type.encode(e.default, buf),
        }
    }

    /// The integer value of `index`:`sub` ("EtherCAT Rx SDO Info" numbering,
    /// aliases followed; live entries as last set in the RAM image).
    pub fn get(&self, index: u16, sub: u8) -> Result<i64, SdoAbort> {
        // a cached entry straight from its packed words (issue 36: the
        // snapshot's ~250 reads after a configuration change)
        if let Some(v) = cached(index, sub).and_then(|(word, value)| load_packed(&self.image, word, value)) {
            return v;
        }
        if let Some(r) = resolve(index, sub) {
            return match r.place {
                Place::Ram(at) => load(&self.image, usize::from(at), r.data_type),
                Place::Const(v) => Ok(v),
            };
        }
        let loc = follow(canonical(index, sub)?)?;
        let t = loc.data_type()?;
        let mut buf = [0u8; 8];
        let n = self.read_loc(loc, &mut buf)?;
        t.decode(buf.get(..n).ok_or(SdoAbort::GENERAL)?)
    }

    /// Sets `index`:`sub` from the runtime (statusword, actual values, ESM
    /// state, …): no access, state or level check, only the type's bounds.
    /// "EtherCAT Rx SDO Info" numbering; entries without a RAM slot
    /// (constants) answer 0601 0002h.
    pub fn set(&mut self, index: u16, sub: u8, value: i64) -> Result<(), SdoAbort> {
        // a cached RAM integer straight from its packed words (issue 36)
        if let Some(r) =
            cached(index, sub).and_then(|(word, at)| store_packed(&mut self.image, word, at, value))
        {
            return r.map(|config| {
                if config {
                    self.config_changed_at(index);
                }
            });
        }
        self.set_general(index, sub, value)
    }

    /// [`set`](Self::set) through the entry's resolution.
    fn set_general(&mut self, index: u16, sub: u8, value: i64) -> Result<(), SdoAbort> {
        let resolved = resolve(index, sub);
        let t = match resolved {
            Some(r) => r.data_type,
            None => follow(canonical(index, sub)?)?.data_type()?,
        };
        if !t.is_integer() && t != DataType::F32 {
            return Err(SdoAbort::TYPE_MISMATCH);
        }
        if t.is_integer() && (value < t.min_value() || value > t.max_value()) {
            return Err(if value < t.min_value() {
                SdoAbort::VALUE_TOO_LOW
            } else {
                SdoAbort::VALUE_TOO_HIGH
            });
        }
        if let Some(r) = resolved {
            let Place::Ram(at) = r.place else {
                return Err(SdoAbort::READ_ONLY);
            };
            let at = usize::from(at);
            let slot = self.image.get_mut(at..at + t.bytes()).ok_or(SdoAbort::GENERAL)?;
            let mut new = [0u8; 8];
            let n = t.encode(value, &mut new)?;
            let new = new.get(..n).ok_or(SdoAbort::GENERAL)?;
            if slot != new {
                for (d, s) in slot.iter_mut().zip(new) {
                    *d = *s;
                }
                if r.config {
                    self.config_changed_at(index);
                }
            }
            return Ok(());
        }
        let mut raw = [0u8; 8];
        let n = t.encode(value, &mut raw)?;
        self.set_bytes(index, sub, raw.get(..n).ok_or(SdoAbort::GENERAL)?)
    }

    /// Sets `index`:`sub` from raw little-endian bytes or string bytes (e.g.
    /// the A257 texts), like [`set`](Self::set); strings shorter than the
    /// entry are padded with 0.
    pub fn set_bytes(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), SdoAbort> {
        if let Some(Resolved {
            place: Place::Ram(at),
            data_type,
            config,
            ..
        }) = resolve(index, sub)
        {
            // a scalar of its full width: straight into its slot
            if data.len() == data_type.bytes() {
                let at = usize::from(at);
                let slot = self.image.get_mut(at..at + data.len()).ok_or(SdoAbort::GENERAL)?;
                if slot != data {
                    for (d, s) in slot.iter_mut().zip(data) {
                        *d = *s;
                    }
                    if config {
                        self.config_changed_at(index);
                    }
                }
                return Ok(());
            }
        }
        let loc = follow(canonical(index, sub)?)?;
        if !in_ram(loc)? {
            return Err(SdoAbort::READ_ONLY);
        }
        loc.data_type()?.check_len(data.len())?;
        self.store(loc, data)
    }

    fn store(&mut self, loc: Loc, data: &[u8]) -> Result<(), SdoAbort> {
        let object = loc.object()?;
        let config = is_config(object);
        let slot = self.image.get_mut(loc.slot()?).ok_or(SdoAbort::GENERAL)?;
        if data.len() > slot.len() {
            return Err(SdoAbort::LENGTH_TOO_HIGH);
        }
        let mut changed = false;
        for (k, d) in slot.iter_mut().enumerate() {
            let v = data.get(k).copied().unwrap_or(0);
            changed |= *d != v;
            *d = v;
        }
        if changed && config {
            self.config_changed_at(object.info.index);
        }
        Ok(())
    }

    /// A bus read; `channel`: in the parameter channel's representation.
    fn read_with<L: LiveValues + ?Sized>(
        &self,
        live: &mut L,
        index: u16,
        sub: u8,
        buf: &mut [u8],
        channel: bool,
    ) -> Result<usize, SdoAbort> {
        let loc = self.locate(index, sub)?;
        if !loc.record()?.access().readable() {
            return Err(SdoAbort::WRITE_ONLY);
        }
        let target = follow(loc)?;
        let o = target.object()?;
        let owned = match o.value {
            Value::Live | Value::Provided => live.read(o.info.index, target.record()?.sub(), buf),
            _ => None,
        };
        let n = match owned {
            Some(r) => r?,
            None => self.read_loc(target, buf)?,
        };
        if channel {
            let shift = self.channel_shift(o.info.index, target.record()?.sub());
            if shift != 0 {
                return Self::channel_read(buf, n, shift, target.data_type()?);
            }
        }
        Ok(n)
    }

    /// A bus write; `channel`: in the parameter channel's representation.
    fn write_with<L: LiveValues + ?Sized>(
        &mut self,
        live: &mut L,
        index: u16,
        sub: u8,
        data: &[u8],
        state: CommState,
        channel: bool,
    ) -> Result<(), SdoAbort> {
        let loc = self.locate(index, sub)?;
        let access = loc.record()?.access();
        if !access.writable() {
            return Err(SdoAbort::READ_ONLY);
        }
        if !access.writable_in(state.access_bit()) {
            return Err(SdoAbort::DEVICE_STATE);
        }
        let target = follow(loc)?;
        let (o, e) = (target.object()?, target.entry()?);
        e.data_type.check_len(data.len())?;
        let mut value = if e.data_type.is_string() {
            None
        } else {
            Some(e.data_type.decode(data)?)
        };
        // the parameter channel's value of a scaled entry → the value kept
        let mut kept = [0u8; 8];
        let mut data = data;
        if let (true, Some(v)) = (channel, value) {
            let shift = self.channel_shift(o.info.index, e.sub);
            if shift != 0 {
                let v = self.channel_write(target, e.data_type, v, shift)?;
                e.check_range(v)?;
                let n = e.data_type.encode(v, &mut kept)?;
                data = kept.get(..n).ok_or(SdoAbort::GENERAL)?;
                value = Some(v);
            }
        }
        if let Some(v) = value {
            self.check_consistency(o, &e, v)?;
            e.check_range(v)?;
            if let Some(list) = enumeration(o.info.index, e.sub) {
                if !list.contains(&v) {
                    return Err(SdoAbort::INVALID_VALUE);
                }
            }
        }
        if o.value == Value::Live {
            live.write(o.info.index, e.sub, data)?;
        }
        if o.value == Value::Provided {
            // the provider keeps the value; nothing in the RAM image
            return live.provide(o.info.index, e.sub, data);
        }
        match (o.value, o.info.index) {
            (Value::Command, 0x1010) => self.requests.save = true,
            (Value::Command, _) => {
                self.restore_defaults();
                self.requests.defaults_restored = true;
            }
            _ => {
                self.record_write_check(o.info.index);
                self.store(target, data)?;
                self.side_effects(o.info.index, e.sub, value);
                self.record_written(o.info.index, e.sub, value);
            }
        }
        Ok(())
    }

    /// Actions started by a write: A00[0] = 1 save, A09[0] = 1 restart.
    fn side_effects(&mut self, index: u16, sub: u8, value: Option<i64>) {
        match (index, sub, value) {
            (0x2000, 1, Some(1)) => self.requests.save = true,
            (0x2009, 1, Some(1)) => self.requests.restart = true,
            // E-148: F050h follows the axis channels' mapping
            (0x1600 | 0x1601 | 0x1A00 | 0x1A01, 0, _) => self.refresh_module_idents(),
            _ => {}
        }
    }

    fn object_info(&self, o: &'static Object) -> Option<&'static ObjectInfo> {
        self.visible(o)
            .then(|| self.variant.declared(o).view(self.sdo_info()))
    }
}

impl Dictionary for DriveObjects {
    fn object(&self, index: u16) -> Option<&'static ObjectInfo> {
        find(index).and_then(|(_, o)| self.object_info(o))
    }

    fn next_object(&self, after: Option<u16>) -> Option<&'static ObjectInfo> {
        let start = after.map_or(0, |a| OBJECTS.partition_point(|o| o.info.index <= a));
        OBJECTS.get(start..)?.iter().find_map(|o| self.object_info(o))
    }

    fn read(&mut self, index: u16, sub: u8, buf: &mut [u8], _state: CommState) -> Result<usize, SdoAbort> {
        self.read_with(&mut NoLive, index, sub, buf, false)
    }

    fn write(&mut self, index: u16, sub: u8, data: &[u8], state: CommState) -> Result<(), SdoAbort> {
        self.write_with(&mut NoLive, index, sub, data, state, false)
    }

    fn process_data_bytes(&self) -> Option<(usize, usize)> {
        let generation = self.config_generation;
        let bytes = match self.pdo_bytes.get() {
            Some((g, bytes)) if g == generation => bytes,
            _ => {
                let bytes = (self.sm_bytes(0x1C12), self.sm_bytes(0x1C13));
                self.pdo_bytes.set(Some((generation, bytes)));
                bytes
            }
        };
        Some(bytes)
    }

    fn sdo_info_enabled(&self) -> bool {
        self.sdo_info()
    }

    fn listed(&self, index: u16) -> bool {
        let a268 = crate::params::A268;
        // the groups (sub 2) matter in the manufacturer area only
        let groups = || self.get(a268, 2);
        sdo_info_selection(self.get(a268, 1), groups, index)
    }
}

/// E-083: is `index` in the SDO Info lists under A268 = (`area`, `groups`)?
/// The manufacturer area is 2000h…5FFFh (axis A and the device) and
/// A000h…DFFFh (axis B), group A at 2000h/A000h, 200h per group; everything
/// else is the standard area. A value that cannot be read lists all.
fn sdo_info_selection(
    area: Result<i64, SdoAbort>,
    groups: impl FnOnce() -> Result<i64, SdoAbort>,
    index: u16,
) -> bool {
    let group = match index & 0x7FFF {
        i @ 0x2000..=0x5FFF => Some((i - 0x2000) >> 9),
        _ => None,
    };
    let in_groups = |g: u16| groups().map_or(true, |bits| bits >> g & 1 != 0);
    match (area.unwrap_or(2), group) {
        (0, g) => g.is_none(),
        (1, None) => false,
        (_, None) => true,
        (_, Some(g)) => in_groups(g),
    }
}

impl<L: LiveValues + ?Sized> Dictionary for WithLive<'_, L> {
    fn object(&self, index: u16) -> Option<&'static ObjectInfo> {
        self.objects.object(index)
    }

    fn next_object(&self, after: Option<u16>) -> Option<&'static ObjectInfo> {
        self.objects.next_object(after)
    }

    fn read(&mut self, index: u16, sub: u8, buf: &mut [u8], _state: CommState) -> Result<usize, SdoAbort> {
        self.objects.read_with(self.live, index, sub, buf, self.channel)
    }

    fn write(&mut self, index: u16, sub: u8, data: &[u8], state: CommState) -> Result<(), SdoAbort> {
        self.objects
            .write_with(self.live, index, sub, data, state, self.channel)
    }

    fn process_data_bytes(&self) -> Option<(usize, usize)> {
        self.objects.process_data_bytes()
    }

    fn sdo_info_enabled(&self) -> bool {
        self.objects.sdo_info_enabled()
    }

    fn listed(&self, index: u16) -> bool {
        self.objects.listed(index)
    }
}
