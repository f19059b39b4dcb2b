//! The drive's parameters as the PROFIdrive profile sees them
//! ([`profidrive::ParamAccess`]): the PNU catalogue ([`super::pnu`]) with
//! its unit conversions, and every CANopen object of the drive as it is
//! (P-045, P-194: in the CiA 402 factor group's units), both through the
//! core's object dictionary with its access, range and state checks.

use super::lookup::{self, Core, CoreSlots, Handle, PreparedCache, WrittenConfig};
use super::pnu::{Jog, Pnu, RecordField, Source, Unit};
use super::units::{self, UnitsCache};
use drive_core::axis::Axis;
use drive_core::faults::E82_INACTIVE;
use drive_core::objects::records::{Record, JOG_NEGATIVE, JOG_POSITIVE};
use drive_core::params::{E43, E82};
use drive_core::user_units::UserUnits;
use drive_core::{DriveObjects, LiveValues};
use motion::units::UnitProfile;
use od::{CommState, DataType, Dictionary, SdoAbort};
use profidrive::telegram::compiled::SlotAccess;
use profidrive::telegram::Dir;
use profidrive::{Addr, Completion, Describe, ParamAccess, PdError};
use profinet::model;

/// The profile's own values, kept between cycles.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct OwnValues {
    /// CW1 as last received or written (967).
    pub cw1: u16,
    /// ZSW1 as last computed (968).
    pub zsw1: u16,
    /// The homing method in PROFIdrive numbering (1050).
    pub homing_method: i8,
    /// 2415h.02 current limit, mA.
    pub current_limit_ma: i32,
    /// 2416h.02 speed limit.
    pub speed_limit: i32,
    /// A save asked through PNU 971 and not yet done.
    pub save_requested: bool,
    /// A save is running or asked (PNU 971 reads 1).
    pub saving: bool,
    /// The telegram editor (PNU 2020…2022).
    pub edit: super::telegram_config::TelegramEdit,
}

/// The PNU 1050 methods and the core's 6098h codes (spec §8.5: the
/// numbering differs from CiA 402 for index pulse, current position and
/// the mechanical stop; −23/−27 have no core method).
pub const HOMING_METHODS: [(i8, i8); 14] = [
    (-18, -1),
    (-17, -2),
    (-2, -3),
    (-1, -4),
    (1, 1),
    (2, 2),
    (7, 7),
    (11, 11),
    (17, 17),
    (18, 18),
    (23, 23),
    (27, 27),
    (32, 33),
    (33, 34),
];

/// The 6098h code of PROFIdrive method `m` (34 → 37, current position).
pub fn core_homing_method(m: i8) -> Option<i8> {
    if m == 34 {
        return Some(37);
    }
    HOMING_METHODS
        .iter()
        .find(|(pd, _)| *pd == m)
        .map(|(_, core)| *core)
}

/// An SDO abort as the PROFIdrive error it means.
pub fn pd_error(a: SdoAbort) -> PdError {
    match a {
        SdoAbort::NO_OBJECT => PdError::IMPERMISSIBLE_PNU,
        SdoAbort::NO_SUBINDEX => PdError::FAULTY_SUBINDEX,
        SdoAbort::READ_ONLY | SdoAbort::WRITE_ONLY | SdoAbort::UNSUPPORTED_ACCESS => PdError::CANNOT_CHANGE,
        SdoAbort::VALUE_TOO_HIGH | SdoAbort::VALUE_TOO_LOW | SdoAbort::MAX_BELOW_MIN => {
            PdError::LIMIT_EXCEEDED
        }
        SdoAbort::INVALID_VALUE => PdError::VALUE_IMPERMISSIBLE,
        SdoAbort::TYPE_MISMATCH | SdoAbort::LENGTH_TOO_HIGH | SdoAbort::LENGTH_TOO_LOW => {
            PdError::INCORRECT_DATA_TYPE
        }
        _ => PdError::NOT_IN_STATE,
    }
}

fn size(t: DataType) -> usize {
    match t {
        DataType::Bool | DataType::I8 | DataType::U8 => 1,
        DataType::I16 | DataType::U16 => 2,
        DataType::I32 | DataType::U32 | DataType::F32 => 4,
        _ => 8,
    }
}

fn signed(t: DataType) -> bool {
    matches!(t, DataType::I8 | DataType::I16 | DataType::I32 | DataType::I64)
}

/// The smallest and largest value of `t` (64-bit types: all of `i64`).
fn type_limits(t: DataType) -> (i64, i64) {
    let bits = 8 * size(t) as u32;
    match (bits, signed(t)) {
        (64, _) => (i64::MIN, i64::MAX),
        (b, true) => (-(1i64 << (b - 1)), (1i64 << (b - 1)) - 1),
        (b, false) => (0, (1i64 << b) - 1),
    }
}

/// The drive as the profile reaches it, for one cycle or one request.
pub struct DriveAccess<'a> {
    /// The object dictionary.
    pub objects: &'a mut DriveObjects,
    /// The axis the profile drives (A).
    pub axis: &'a Axis,
    /// The PROFINET units of the PNUs.
    pub units: &'a UnitProfile,
    /// The axis' CiA 402 user units, read once per configuration
    /// generation.
    pub user_units: &'a mut UnitsCache,
    /// The CiA 402 entries accessed, prepared once per configuration
    /// generation.
    pub prepared: &'a mut PreparedCache,
    /// The core entries the profile reads itself, resolved.
    pub core: &'a CoreSlots,
    /// The configuration entries the telegram wrote last, with the
    /// configuration generation after the write (issue 36).
    pub written: &'a mut WrittenConfig,
    /// The profile's own values.
    pub own: &'a mut OwnValues,
    /// The provider of the live entries a parameter access reaches (the
    /// scope's group T); [`NoLive`](drive_core::NoLive) where none can be.
    pub live: &'a mut dyn LiveValues,
    /// A record a telegram's fields wrote, not yet stored: the fields of
    /// one record that follow each other in a telegram (target, velocities,
    /// accelerations) store it and show it in the window J401 once, not
    /// once per field (issue 36). Stored before any other access and when
    /// the access ends ([`flush_record`](DriveAccess::flush_record)).
    /// With it the record as it was read: a telegram that sends the same
    /// values every cycle stores nothing (the window J401 shows the stored
    /// record already: every write of J401 or the selector keeps the two
    /// alike). The flag: `n` is the selected record (J400), which cannot
    /// change while the record is pending (any other access stores it
    /// first), so the next field of it does not read J400 again.
    pub(super) pending: Option<(u8, u16, bool, Record, Record)>,
}

mod records;

impl Drop for DriveAccess<'_> {
    fn drop(&mut self) {
        self.flush_record();
    }
}

impl DriveAccess<'_> {
    fn index(&self, index: u16) -> u16 {
        if (0x6000..0x6800).contains(&index) {
            self.axis.cia402_index(index)
        } else if (0x2000..0x6000).contains(&index) {
            self.axis.manufacturer_index(index)
        } else {
            index
        }
    }

    /// Whether a changed value written to `addr` (a PNU or an object) is a
    /// configuration change ([`DriveObjects::config_generation`]): an
    /// object in RAM that is no cyclic set-point, and the vl ramps of PNU
    /// 1011.2. Records, the profile's own values and unknown addresses are
    /// none.
    pub fn is_config_entry(&self, addr: Addr) -> bool {
        let config = |index: u16, sub: u8| {
            self.objects
                .slot(self.index(index), sub)
                .is_some_and(|s| s.is_config())
        };
        let p = match lookup::memoised(addr) {
            Some(p) => p,
            None if !lookup::is_catalogue_index(addr.index) => return config(addr.index, addr.sub),
            None => match lookup::find_and_remember(addr) {
                Ok(p) => p,
                Err(_) => return false,
            },
        };
        match p.source {
            Source::Object { index, sub } => config(index, sub),
            Source::VlBothRamps => true,
            _ => false,
        }
    }

    fn user_units(&mut self) -> &UserUnits {
        self.user_units.get(self.objects, self.axis)
    }

    /// The declaration of `index`:`sub`: 0x00 without the object, 0x03
    /// without the subindex.
    fn entry(&self, index: u16, sub: u8) -> Result<od::EntryInfo, PdError> {
        self.objects
            .object(index)
            .ok_or(PdError::IMPERMISSIBLE_PNU)?
            .entry(sub)
            .ok_or(PdError::FAULTY_SUBINDEX)
    }

    /// An object's value through the dictionary (Op, its access rules);
    /// a CiA 402 entry through its prepared access (the same answers).
    fn read_object(&mut self, index: u16, sub: u8) -> Result<i64, PdError> {
        let t = match self.prepared.get(self.objects, index, sub) {
            Some(p) => match self.objects.read_prepared(p) {
                Some(v) => return Ok(v),
                None => p.data_type(),
            },
            None => self.entry(index, sub)?.data_type,
        };
        let mut buf = [0u8; 8];
        let n = self.read_full(index, sub, &mut buf)?;
        let mut v: u64 = 0;
        for (k, b) in buf.iter().take(n.min(8)).enumerate() {
            v |= u64::from(*b) << (8 * k);
        }
        let bits = 8 * n.min(8) as u32;
        Ok(
            if signed(t) && bits < 64 && bits > 0 && v & (1 << (bits - 1)) != 0 {
                (v | (u64::MAX << bits)) as i64
            } else {
                v as i64
            },
        )
    }

    fn read_full(&mut self, index: u16, sub: u8, buf: &mut [u8]) -> Result<usize, PdError> {
        self.objects
            .with_live(self.live)
            .read(index, sub, buf, CommState::Op)
            .map_err(pd_error)
    }

    /// Writes `value` (the object's units) into `index`:`sub`; a value
    /// beyond the object's type is refused with 0x02 (never cut to its low
    /// bytes).
    fn write_object(&mut self, index: u16, sub: u8, value: i64) -> Result<(), PdError> {
        let bytes = value.to_le_bytes();
        let fits = |t: DataType| {
            let (min, max) = type_limits(t);
            if (min..=max).contains(&value) {
                Ok(())
            } else {
                Err(PdError::LIMIT_EXCEEDED)
            }
        };
        let t = match self.prepared.get(self.objects, index, sub) {
            Some(p) => {
                fits(p.data_type())?;
                let data = bytes
                    .get(..size(p.data_type()))
                    .ok_or(PdError::INCORRECT_DATA_TYPE)?;
                if let Some(r) = self.objects.write_prepared(p, data) {
                    return r.map_err(pd_error);
                }
                p.data_type()
            }
            None => self.entry(index, sub)?.data_type,
        };
        self.written.unprepared = true;
        fits(t)?;
        let data = bytes.get(..size(t)).ok_or(PdError::INCORRECT_DATA_TYPE)?;
        self.objects
            .with_live(self.live)
            .write(index, sub, data, CommState::Op)
            .map_err(pd_error)
    }

    /// Bus units → the object's units (remembered per configuration
    /// generation, [`UnitsCache::converted`]).
    pub(super) fn object_of(&mut self, unit: Unit, bus: i64) -> Result<i64, PdError> {
        if unit == Unit::None {
            return Ok(bus);
        }
        let (g, axis, code) = (
            self.objects.config_generation(),
            self.axis.index(),
            unit as u8 + 1,
        );
        if let Some(v) = self.user_units.converted(g, axis, code, bus) {
            return Ok(v);
        }
        let v = self.convert(unit, bus)?;
        self.user_units.remember(g, axis, code, bus, v);
        Ok(v)
    }

    /// [`object_of`](Self::object_of) computed.
    pub(super) fn convert(&mut self, unit: Unit, bus: i64) -> Result<i64, PdError> {
        let range = PdError::LIMIT_EXCEEDED;
        let p = self.units;
        Ok(match unit {
            Unit::None => bus,
            Unit::Position => {
                let inc = units::from_bus(&p.position, bus).map_err(|_| range)?;
                self.user_units().position_from_increments(inc).ok_or(range)?
            }
            // the integer path: exact to the increment (f32 is not, above 2^24)
            Unit::Velocity => {
                let inc = units::from_bus(&p.velocity, bus).map_err(|_| range)?;
                units::velocity_from_increments(self.user_units(), inc)
            }
            Unit::Acceleration => {
                let inc = units::from_bus(&p.acceleration, bus).map_err(|_| range)?;
                units::acceleration_from_increments(self.user_units(), inc)
            }
            Unit::Rpm => units::rpm_of(units::from_bus(&p.velocity, bus).map_err(|_| range)?),
            Unit::RpmPerSecond => units::rpm_of(units::from_bus(&p.acceleration, bus).map_err(|_| range)?),
        })
    }

    /// [`Self::object_of`] for a write of `index`:`sub`, where the bus value a
    /// read of the type's limit returns writes that limit: a value read can
    /// be written back although its rounding lands just beyond the type
    /// (PNU 1273's default `u32::MAX` increments reads 4 096 000/1000 rev,
    /// which converts to 2^32 increments).
    fn object_value_read_back(&mut self, unit: Unit, bus: i64, index: u16, sub: u8) -> Result<i64, PdError> {
        let v = self.object_of(unit, bus)?;
        // the data type from the prepared access where there is one (the
        // write after this uses it): no lookup in the dictionary's tables
        let t = match self.prepared.get(self.objects, index, sub) {
            Some(p) => p.data_type(),
            None => self.entry(index, sub)?.data_type,
        };
        let (min, max) = type_limits(t);
        if v > max && self.bus_of(unit, max) == Ok(bus) {
            return Ok(max);
        }
        if v < min && self.bus_of(unit, min) == Ok(bus) {
            return Ok(min);
        }
        Ok(v)
    }

    /// The object's units → bus units.
    fn bus_of(&mut self, unit: Unit, object: i64) -> Result<i64, PdError> {
        let range = PdError::LIMIT_EXCEEDED;
        let p = self.units;
        let v = match unit {
            Unit::None => return Ok(object),
            Unit::Position => {
                let inc = self.user_units().position_to_increments(object).ok_or(range)?;
                units::to_bus(&p.position, inc)
            }
            Unit::Velocity => units::to_bus(
                &p.velocity,
                units::velocity_to_increments(self.user_units(), object),
            ),
            Unit::Acceleration => units::to_bus(
                &p.acceleration,
                units::acceleration_to_increments(self.user_units(), object),
            ),
            Unit::Rpm => units::to_bus(&p.velocity, units::increments_of_rpm(object)),
            Unit::RpmPerSecond => units::to_bus(&p.acceleration, units::increments_of_rpm(object)),
        };
        v.map(i64::from).map_err(|_| range)
    }

    /// 6060h code ⇄ PNU 1500 code.
    fn operating_mode(&self) -> i64 {
        // (a missing 6061h reads 0: no mode either way)
        match self.core.get(self.objects, self.axis, Core::ModeDisplay) {
            // positioning, with homing and jog inside it
            1 | 6 | -1 => 0x10,
            2 | 3 => 0x08,
            4 => 0x04,
            _ => 0,
        }
    }

    fn identification(sub: u8) -> i64 {
        let (_, major, minor, _) = model::SOFTWARE_REVISION;
        match sub {
            0 => i64::from(model::VENDOR_ID),
            1 => i64::from(model::DEVICE_ID),
            2 => i64::from(u16::from(major) << 8 | u16::from(minor)),
            3 => 2026,
            // DDMMh: 1 December
            _ => 0x0112,
        }
    }

    fn last_error(&self) -> i64 {
        let e82 = self.objects.get(E82, 0).unwrap_or(0);
        if e82 == i64::from(E82_INACTIVE) || e82 == 0 {
            return 0;
        }
        let e43 = self.objects.get(E43, 0).unwrap_or(0).clamp(0, 15);
        (e82 << 4) | e43
    }

    /// 60FDh in the manual's PNU 1141 map (limit switch 0 = negative: bit 7,
    /// limit switch 1 = positive: bit 8).
    fn digital_inputs(&self) -> i64 {
        let d = self.core.get(self.objects, self.axis, Core::Inputs);
        ((d & 1) << 7) | ((d >> 1 & 1) << 8)
    }
}

impl ParamAccess for DriveAccess<'_> {
    fn describe(&self, addr: Addr) -> Result<Describe, PdError> {
        if lookup::is_catalogue_index(addr.index) {
            let p = lookup::find(addr)?;
            return Ok(Describe {
                data_type: p.data_type,
                readable: p.readable,
                writable: p.writable,
            });
        }
        let e = self.entry(self.index(addr.index), addr.sub)?;
        Ok(Describe {
            data_type: e.data_type,
            readable: e.access.readable(),
            writable: e.access.writable(),
        })
    }

    fn read(&mut self, addr: Addr) -> Result<i64, PdError> {
        self.flush_record();
        // a catalogue entry the memo holds: no search (its index is one)
        let p = match lookup::memoised(addr) {
            Some(p) => p,
            None => {
                if !lookup::is_catalogue_index(addr.index) {
                    let index = self.index(addr.index);
                    return self.read_object(index, addr.sub);
                }
                lookup::find_and_remember(addr)?
            }
        };
        self.read_pnu(p, addr)
    }

    fn write(&mut self, addr: Addr, value: i64, _cyclic: bool) -> Result<Completion, PdError> {
        // every write here is a RAM write: the store is written only by a save
        let p = match lookup::memoised(addr) {
            Some(p) => p,
            None => {
                if !lookup::is_catalogue_index(addr.index) {
                    self.flush_record();
                    let index = self.index(addr.index);
                    self.write_object(index, addr.sub, value)?;
                    return Ok(Completion::Done);
                }
                lookup::find_and_remember(addr)?
            }
        };
        self.write_pnu(p, addr, value)
    }

    fn poll_write(&mut self, addr: Addr) -> Result<Completion, PdError> {
        if addr == Addr::new(971, 0) && self.own.saving {
            return Ok(Completion::Pending);
        }
        if addr.index == super::telegram_config::SELECT || addr.index == super::telegram_config::APPLY {
            return self.own.edit.poll();
        }
        Ok(Completion::Done)
    }
}

impl SlotAccess for DriveAccess<'_> {
    type Handle = Handle;

    fn resolve(&mut self, dir: Dir, addr: Addr) -> Option<Handle> {
        let config = dir == Dir::Receive && self.is_config_entry(addr);
        if lookup::is_catalogue_index(addr.index) {
            // an address the catalogue does not hold: the address path
            // answers its error
            Handle::pnu(lookup::position(addr).ok()?, config)
        } else {
            Handle::object(config)
        }
    }

    fn write_handle(&mut self, h: Handle, addr: Addr, value: i64) -> Result<Completion, PdError> {
        if h.is_config() {
            return self.write_config(h, addr, value);
        }
        self.write_resolved(h, addr, value)
    }

    fn read_handle(&mut self, h: Handle, addr: Addr) -> Result<i64, PdError> {
        self.flush_record();
        match h.entry() {
            Some(p) => self.read_pnu(p, addr),
            None => {
                let index = self.index(addr.index);
                self.read_object(index, addr.sub)
            }
        }
    }
}

impl DriveAccess<'_> {
    /// [`SlotAccess::write_handle`] of a configuration entry (out of line:
    /// the other entries' path stays as short as it was).
    #[inline(never)]
    fn write_config(&mut self, h: Handle, addr: Addr, value: i64) -> Result<Completion, PdError> {
        // a configuration entry (telegram 1's ramps): the same value
        // written before with no configuration change since left its
        // objects as this write would (every change of a configuration
        // value moves the generation) and was taken (the checks of a
        // prepared write depend on the value and the configuration only)
        let key = WrittenConfig::key(self.axis.index(), addr);
        if self.written.holds(key, value, self.objects.config_generation()) {
            self.flush_record();
            return Ok(Completion::Done);
        }
        self.written.unprepared = false;
        let r = self.write_resolved(h, addr, value);
        if r == Ok(Completion::Done) && !self.written.unprepared {
            self.written.put(key, value, self.objects.config_generation());
        }
        r
    }

    /// [`SlotAccess::write_handle`] without the memo of configuration
    /// entries.
    #[inline(always)]
    fn write_resolved(&mut self, h: Handle, addr: Addr, value: i64) -> Result<Completion, PdError> {
        match h.entry() {
            Some(p) => self.write_pnu(p, addr, value),
            None => {
                self.flush_record();
                let index = self.index(addr.index);
                self.write_object(index, addr.sub, value)?;
                Ok(Completion::Done)
            }
        }
    }

    /// [`ParamAccess::read`] of the catalogue entry `p` (`addr`), the
    /// pending record stored.
    fn read_pnu(&mut self, p: &'static Pnu, addr: Addr) -> Result<i64, PdError> {
        match p.source {
            Source::Object { index, sub } => {
                let index = self.index(index);
                let v = self.read_object(index, sub)?;
                self.bus_of(p.unit, v)
            }
            Source::SelectedRecord(f) => self.read_record(None, f, p.unit),
            Source::JogRecord(j, f) => self.read_record(Some(j), f, p.unit),
            Source::VlBothRamps => {
                let index = self.index(0x6048);
                let v = self.read_object(index, 1)?;
                self.bus_of(p.unit, v)
            }
            Source::Cw1 => Ok(i64::from(self.own.cw1)),
            Source::Zsw1 => Ok(i64::from(self.own.zsw1)),
            Source::OperatingMode => Ok(self.operating_mode()),
            Source::HomingMethod => Ok(i64::from(self.own.homing_method)),
            Source::DigitalInputs => Ok(self.digital_inputs()),
            Source::LastError => Ok(self.last_error()),
            Source::Identification => Ok(Self::identification(addr.sub)),
            Source::Save => Ok(i64::from(self.own.saving)),
            Source::TelegramEditor => {
                let edit = self.own.edit;
                edit.read(addr, self)
            }
            Source::ProfileType => Ok(0),
            Source::Own => Ok(i64::from(if addr.index == 0x2415 {
                self.own.current_limit_ma
            } else {
                self.own.speed_limit
            })),
        }
    }

    /// [`ParamAccess::write`] of the catalogue entry `p` (`addr`).
    fn write_pnu(&mut self, p: &'static Pnu, addr: Addr, value: i64) -> Result<Completion, PdError> {
        if !matches!(p.source, Source::SelectedRecord(_) | Source::JogRecord(..)) {
            self.flush_record();
        }
        if !p.writable {
            return Err(PdError::CANNOT_CHANGE);
        }
        match p.source {
            Source::Object { index, sub } => {
                let index = self.index(index);
                let v = self.object_value_read_back(p.unit, value, index, sub)?;
                self.write_object(index, sub, v)?;
            }
            Source::SelectedRecord(f) => self.write_record(None, f, p.unit, value)?,
            Source::JogRecord(j, f) => self.write_record(Some(j), f, p.unit, value)?,
            Source::VlBothRamps => {
                let v = self.object_of(p.unit, value)?;
                for i in [0x6048, 0x6049] {
                    let index = self.index(i);
                    self.write_object(index, 1, v)?;
                    self.write_object(index, 2, 1)?;
                }
            }
            Source::Cw1 => self.own.cw1 = u16::try_from(value).map_err(|_| PdError::LIMIT_EXCEEDED)?,
            Source::OperatingMode => {
                let code = match value {
                    0x10 => 1,
                    0x08 => 2,
                    0x04 => 4,
                    _ => return Err(PdError::VALUE_IMPERMISSIBLE),
                };
                let index = self.index(0x6060);
                self.write_object(index, 0, code)?;
            }
            Source::HomingMethod => {
                let m = i8::try_from(value).map_err(|_| PdError::LIMIT_EXCEEDED)?;
                if core_homing_method(m).is_none() {
                    return Err(PdError::VALUE_IMPERMISSIBLE);
                }
                self.own.homing_method = m;
            }
            Source::Save => match value {
                0 => {}
                1 | 256 => {
                    self.own.save_requested = true;
                    self.own.saving = true;
                    return Ok(Completion::Pending);
                }
                // 257/258: no encoder memory on this drive
                _ => return Err(PdError::VALUE_IMPERMISSIBLE),
            },
            Source::Own => {
                let v = i32::try_from(value).map_err(|_| PdError::LIMIT_EXCEEDED)?;
                if addr.index == 0x2415 {
                    self.own.current_limit_ma = v;
                } else {
                    self.own.speed_limit = v;
                }
            }
            Source::ProfileType => match value {
                0 => {}
                1 => return Err(PdError::VALUE_IMPERMISSIBLE),
                _ => return Err(PdError::LIMIT_EXCEEDED),
            },
            Source::TelegramEditor => {
                let mut edit = self.own.edit;
                let done = edit.write(addr, value, self);
                self.own.edit = edit;
                return done;
            }
            Source::Zsw1 | Source::DigitalInputs | Source::LastError | Source::Identification => {
                return Err(PdError::CANNOT_CHANGE)
            }
        }
        Ok(Completion::Done)
    }
}

impl super::telegram_config::StoreA280 for DriveAccess<'_> {
    fn store_a280(&mut self, set: &profidrive::telegram::TelegramSet) {
        self.objects.store_a280(set);
    }
}
