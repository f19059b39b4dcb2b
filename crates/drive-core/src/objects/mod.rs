//! The declaration: every object of the drive, once, as `const` tables.
//!
//! - [`comm`]: the communication area 1000h–1FFFh and the modular-device
//!   objects F0xxh (ETG.1000.6, ETG.1020, ETG.5000.1; `od-ethercat.md`).
//! - [`manufacturer`]: the manufacturer parameters at 2000h + group·200h + line
//!   (axis-B copies of axis parameters at +8000h; spec §2.6).
//! - [`motor`]: the motor data (group B) and the i²t settings (U10/U11).
//! - [`records`]: the position records, their selector, start number,
//!   override and set-up speed in group J (3390h…339Bh, per-axis ones also
//!   at +8000h).
//! - [`cia402`]: the CiA 402 objects of axis A (6000h–65FFh); axis B is
//!   derived at +800h (`od-cia402.md`).
//! - [`scope`]: the scope's configuration and trace (group T, 4600h…,
//!   answered by the recorder).
//! - [`scaling`]: the entries fieldbus scaling A213 acts on and their
//!   decimal places (A310 velocities, A311 accelerations).
//! - [`single`]: the objects the single-axis device declares differently
//!   (it has no axis-B objects: [`crate::Variant`]).
//!
//! [`OBJECTS`] joins them, sorted by index (checked at compile time);
//! [`OFFSETS`] gives each object's place in the RAM image, computed at compile
//! time. Subindices are declared in the "EtherCAT Rx SDO Info" numbering
//! (element + 1 for manufacturer arrays/records); manufacturer arrays carry
//! the "EtherCAT Rx" view (element = subindex): [`Object::rx`], [`Object::view`].

use od::{Access, DataType, Entries, EntryInfo, ObjectCode, ObjectInfo};

/// Builds a `'static` entry list from entry expressions (the list becomes a
/// `const`, so it can be passed to the `const fn` constructors).
macro_rules! entries {
    ($($e:expr),+ $(,)?) => {{
        const E: &[od::EntryInfo] = &[$($e),+];
        E
    }};
}

/// A manufacturer array/record parameter: its elements with subindex =
/// element number (the "EtherCAT Rx" view, `[…]` or `from <const slice>`);
/// the "EtherCAT Rx SDO Info" view (sub 0 = number of elements, element e at
/// e + 1) is derived, and so are the Rx views of both axis windows.
macro_rules! param_array {
    ($index:expr, $name:expr, $code:ident, $value:expr, [$($el:expr),+ $(,)?]) => {
        param_array!($index, $name, $code, $value, from &[$($el),+])
    };
    ($index:expr, $name:expr, $code:ident, $value:expr, from $els:expr) => {{
        const ELS: &[od::EntryInfo] = $els;
        const INFO: [od::EntryInfo; ELS.len() + 1] = $crate::objects::sdo_info_view(ELS);
        // the "EtherCAT Rx" view is the SDO Info view's elements renumbered
        // from 0 (packing shares their records)
        const _: () = assert!(
            $crate::objects::is_rx_view(ELS, &INFO, $crate::objects::RxView::Elements),
            "manufacturer elements have subindex = element number"
        );
        $crate::objects::Object::new($index, $name, od::ObjectCode::$code, &INFO, $value)
            .rx_view($crate::objects::RxView::Elements)
    }};
}

/// `["<prefix>1", "<prefix>2", …]` for the listed numbers.
macro_rules! numbered {
    ($prefix:literal; $($n:literal)+) => {
        [$(concat!($prefix, $n)),+]
    };
}

pub mod cia402;
pub mod comm;
pub mod control;
mod layout;
pub mod manufacturer;
pub mod motor;
mod pack;
pub mod records;
pub mod scaling;
pub mod scope;
mod shorthand;
pub mod single;
pub mod stage;

pub(crate) use layout::{axis_b_index, cycle, Run, LAYOUT, RX_RUNS, TX_RUNS};
pub use layout::{image_offset, CycleField, AXIS_BLOCK, IMAGE_BYTES, OFFSETS};
pub use pack::{EntryRecord, ENTRY_TABLE};

/// Where the values of an object live.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Value {
    /// Constants: every entry reads its declared default.
    Const,
    /// A constant string (VAR; behind a reference, so that a [`Value`] takes
    /// 8 bytes in the firmware image).
    Text(&'static &'static str),
    /// 1018h: constants, except the revision 1018h:03, which follows the
    /// subindex template (E-008).
    Identity,
    /// The RAM image, initialised from the defaults.
    Ram,
    /// The RAM image, fed by the runtime ([`crate::DriveObjects::set`]) or
    /// answered by a [`crate::LiveValues`] provider: values owned by another
    /// part of the firmware.
    Live,
    /// Command entries (1010h/1011h): reads give the default, a write with the
    /// signature is a command.
    Command,
    /// A manufacturer parameter mirroring another object entry by entry
    /// (entry position k ↔ the target's position k). `sub0`: sub 0 mirrors
    /// too (else it is the parameter's own constant element count).
    Mirror {
        /// The mirrored object.
        index: u16,
        /// Does sub 0 mirror the target's sub 0?
        sub0: bool,
    },
    /// Entry position k is the target entry `(index, sub)` of the list; `(0, 0)`
    /// = the parameter's own constant (behind a reference, as [`Value::Text`]).
    Alias(&'static &'static [(u16, u8)]),
    /// Values only a [`crate::LiveValues`] provider has (the scope's
    /// configuration and trace, [`crate::scope`]): no place in the RAM image,
    /// not saved; without a provider that owns them a read or write answers
    /// 0800 0022h (docs/conformance.md).
    Provided,
}

/// The "EtherCAT Rx" template view of an object (manufacturer arrays and
/// records have element e at subindex e there, at e + 1 in the SDO Info
/// view).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RxView {
    /// The same as in the SDO Info template.
    Same,
    /// The SDO Info view's elements (its entries after sub 0) at subindex - 1.
    Elements,
    /// The same without defaults (a mirror's elements read the target's
    /// values; its view declares none).
    ElementsNoDefaults,
}

/// One object of the drive: its metadata, where its values live and who may
/// see it. Declared with slices of entries; [`OBJECTS`] holds the same objects
/// with their entries in [`ENTRY_TABLE`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Object {
    /// Metadata in the "EtherCAT Rx SDO Info" template (what SDO Info reports).
    pub info: ObjectInfo,
    /// Its view in the "EtherCAT Rx" template ([`Object::view`]).
    pub rx: RxView,
    /// Where the values live.
    pub value: Value,
    /// Access level (0–3) needed to see the object; hidden objects answer
    /// 0602 0000h (E-016). Standard objects: 0.
    pub level: u8,
    /// A per-axis manufacturer parameter (axis-B copy at +8000h).
    pub axis: bool,
    /// Reference note: parameter coordinate, assumptions (host builds only).
    #[cfg(not(target_os = "none"))]
    pub note: &'static str,
}

impl Object {
    /// An object.
    pub const fn new(
        index: u16,
        name: &'static str,
        code: ObjectCode,
        entries: &'static [EntryInfo],
        value: Value,
    ) -> Self {
        Self {
            info: ObjectInfo {
                index,
                name,
                code,
                entries: Entries::slice(entries),
            },
            rx: RxView::Same,
            value,
            level: 0,
            axis: false,
            #[cfg(not(target_os = "none"))]
            note: "",
        }
    }

    /// A VAR object named after its one entry.
    pub const fn var(index: u16, value: Value, entries: &'static [EntryInfo]) -> Self {
        let name = match entries {
            [first, ..] => first.name,
            [] => "",
        };
        Self::new(index, name, ObjectCode::Var, entries, value)
    }

    /// With access level `level`.
    pub const fn level(mut self, level: u8) -> Self {
        self.level = level;
        self
    }

    /// A per-axis parameter (copied to axis B).
    pub const fn axis(mut self) -> Self {
        self.axis = true;
        self
    }

    /// With a reference note. The notes are for the host (the object
    /// reference `doc`, the declaration's tests): a bare-metal build has no
    /// such field and keeps them out of flash.
    #[allow(unused_mut, unused_variables)]
    pub const fn note(mut self, note: &'static str) -> Self {
        #[cfg(not(target_os = "none"))]
        {
            self.note = note;
        }
        self
    }

    /// With the "EtherCAT Rx" template view `rx` (built when the table is
    /// packed).
    pub const fn rx_view(mut self, rx: RxView) -> Self {
        self.rx = rx;
        self
    }

    /// Has a view of its own in the "EtherCAT Rx" template?
    pub const fn has_rx_view(&self) -> bool {
        !matches!(self.rx, RxView::Same)
    }

    /// Bytes this object takes in the RAM image (from a declaration).
    pub const fn declared_ram_bytes(&self) -> usize {
        match self.value {
            Value::Ram | Value::Live => {
                let mut sum = 0;
                let mut rest = declared(self.info.entries);
                while let [e, tail @ ..] = rest {
                    sum += e.data_type.bytes();
                    rest = tail;
                }
                sum
            }
            _ => 0,
        }
    }

    /// Bytes this object takes in the RAM image.
    pub fn ram_bytes(&self) -> usize {
        match self.value {
            Value::Ram | Value::Live => self.info.entries.iter().map(|e| e.data_type.bytes()).sum(),
            _ => 0,
        }
    }

    /// The metadata in the template (`sdo_info` = "EtherCAT Rx SDO Info").
    pub fn view(&self, sdo_info: bool) -> &ObjectInfo {
        if !sdo_info && self.has_rx_view() {
            pack::rx_view(self.info.index).unwrap_or(&self.info)
        } else {
            &self.info
        }
    }
}

/// The entries of a declared object (a slice; empty for packed ones).
pub const fn declared(entries: Entries) -> &'static [EntryInfo] {
    match entries.as_slice() {
        Some(s) => s,
        None => &[],
    }
}

/// Entry `k` of the "EtherCAT Rx" view `rx` of an object with the SDO Info
/// entries `info` (`k + 1 < info.len()`).
pub const fn rx_entry(info: &[EntryInfo], rx: RxView, k: usize) -> EntryInfo {
    // k + 1 < info.len() (compile-time evaluation)
    #[allow(clippy::indexing_slicing)]
    let mut e = info[k + 1].at(k as u8);
    if matches!(rx, RxView::ElementsNoDefaults) {
        e.default = 0;
    }
    e
}

/// Is `list` the "EtherCAT Rx" view `rx` of an object with the SDO Info
/// entries `info`?
pub const fn is_rx_view(list: &[EntryInfo], info: &[EntryInfo], rx: RxView) -> bool {
    if matches!(rx, RxView::Same) || list.len() + 1 != info.len() {
        return false;
    }
    let mut k = 0;
    while k < list.len() {
        // k < list.len() (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        if !od::packed::same_entry(&list[k], &rx_entry(info, rx, k)) {
            return false;
        }
        k += 1;
    }
    true
}

/// "Highest subindex supported" entry of an array/record with `n` entries.
pub const fn count_entry(n: usize) -> EntryInfo {
    EntryInfo::new(0, "Highest subindex supported", DataType::U8, Access::RO).default_value(n as i64)
}

/// The "EtherCAT Rx SDO Info" view of manufacturer elements `els`: sub 0 =
/// number of elements, element e at sub e + 1. `N` = `els.len() + 1`.
pub const fn sdo_info_view<const N: usize>(els: &[EntryInfo]) -> [EntryInfo; N] {
    let mut out = [count_entry(N - 1); N];
    let mut i = 1;
    let mut rest = els;
    while let [e, tail @ ..] = rest {
        // i < N: N = els.len() + 1 (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        {
            out[i] = e.at(i as u8);
        }
        i += 1;
        rest = tail;
    }
    out
}

/// `N` copies of `template` at subindices `first`, `first + 1`, … named by `names`.
pub const fn repeat<const N: usize>(
    template: EntryInfo,
    first: u8,
    names: &[&'static str; N],
) -> [EntryInfo; N] {
    let mut out = [template; N];
    let mut i = 0;
    while i < N {
        // i < N (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        {
            out[i] = template.at(first + i as u8);
            out[i].name = names[i];
        }
        i += 1;
    }
    out
}

/// `objs` with every index moved by `by` (the axis-B copy).
pub const fn offset<const N: usize>(objs: [Object; N], by: u16) -> [Object; N] {
    let mut out = objs;
    let mut i = 0;
    while i < N {
        // i < N (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        {
            assert!(!out[i].has_rx_view(), "CiA 402 objects have one view");
            out[i].info.index += by;
        }
        i += 1;
    }
    out
}

/// Number of per-axis objects in `objs`.
pub const fn count_axis(objs: &[Object]) -> usize {
    let mut n = 0;
    let mut rest = objs;
    while let [o, tail @ ..] = rest {
        if o.axis {
            n += 1;
        }
        rest = tail;
    }
    n
}

const FILLER: Object = Object::new(0, "", ObjectCode::Var, &[], Value::Const);

/// The per-axis objects of `objs`, moved by `by`. `N` = [`count_axis`].
pub const fn axis_copies<const N: usize>(objs: &[Object], by: u16) -> [Object; N] {
    let mut out = [FILLER; N];
    let mut i = 0;
    let mut rest = objs;
    while let [o, tail @ ..] = rest {
        if o.axis {
            // i < N = count_axis(objs) (compile-time evaluation)
            #[allow(clippy::indexing_slicing)]
            {
                out[i] = *o;
                out[i].info.index += by;
            }
            i += 1;
        }
        rest = tail;
    }
    out
}

/// Two lists sorted by index merged into one sorted list of `N` =
/// `a.len() + b.len()` objects (an index in both stays twice: the table's
/// `sorted` check refuses it).
const fn merge<const N: usize>(a: &[Object], b: &[Object]) -> [Object; N] {
    let mut out = [FILLER; N];
    let (mut i, mut j) = (0, 0);
    while i + j < N {
        // i < a.len() or j < b.len() while i + j < N (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        {
            let at = i + j;
            if j >= b.len() || (i < a.len() && a[i].info.index <= b[j].info.index) {
                out[at] = a[i];
                i += 1;
            } else {
                out[at] = b[j];
                j += 1;
            }
        }
    }
    assert!(i == a.len() && j == b.len(), "merged object count");
    out
}

/// The areas joined into one array of `N` objects.
const fn join<const N: usize>(parts: &[&[Object]]) -> [Object; N] {
    let mut out = [FILLER; N];
    let mut i = 0;
    let mut parts = parts;
    while let [part, more @ ..] = parts {
        let mut rest = *part;
        while let [o, tail @ ..] = rest {
            // i < N: N is the sum of the part lengths (compile-time evaluation)
            #[allow(clippy::indexing_slicing)]
            {
                out[i] = *o;
            }
            i += 1;
            rest = tail;
        }
        parts = more;
    }
    assert!(i == N, "object count");
    out
}

const fn sorted(objs: &[Object]) -> bool {
    let mut rest = objs;
    while let [a, tail @ ..] = rest {
        if let [b, ..] = tail {
            if a.info.index >= b.info.index {
                return false;
            }
        }
        rest = tail;
    }
    true
}

const fn entries_sorted(objs: &[Object]) -> bool {
    let mut rest = objs;
    while let [o, tail @ ..] = rest {
        let mut es = declared(o.info.entries);
        while let [a, more @ ..] = es {
            if let [b, ..] = more {
                if a.sub >= b.sub {
                    return false;
                }
            }
            es = more;
        }
        rest = tail;
    }
    true
}

const MOTOR_STAGE: [Object; motor::PARAMS.len() + stage::PARAMS.len()] =
    merge(&motor::PARAMS, &stage::PARAMS);
const SETTINGS_A: [Object; control::PARAMS.len() + MOTOR_STAGE.len()] = merge(&control::PARAMS, &MOTOR_STAGE);
/// The global and axis-A manufacturer parameters: those of [`manufacturer`],
/// the control settings of [`control`], the motor data of [`motor`] and the
/// power stage's data of [`stage`], merged by index.
pub const MANUFACTURER_A: [Object; manufacturer::PARAMS.len() + SETTINGS_A.len()] =
    merge(&manufacturer::PARAMS, &SETTINGS_A);
const AXIS_B_PARAMS: usize = count_axis(&MANUFACTURER_A);
const MANUFACTURER_B: [Object; AXIS_B_PARAMS] = axis_copies(&MANUFACTURER_A, crate::AXIS_B_MANUFACTURER);
const AXIS_B_RECORDS: usize = count_axis(&records::PARAMS);
const RECORDS_B: [Object; AXIS_B_RECORDS] = axis_copies(&records::PARAMS, crate::AXIS_B_MANUFACTURER);
const PROTECTION_B: [Object; motor::PROTECTION.len()] =
    axis_copies(&motor::PROTECTION, crate::AXIS_B_MANUFACTURER);
const CIA402_B: [Object; cia402::AXIS_A.len()] = offset(cia402::AXIS_A, crate::AXIS_B_CIA402);

/// Number of objects.
pub const COUNT: usize = comm::COMM.len()
    + MANUFACTURER_A.len()
    + records::PARAMS.len()
    + scope::PARAMS.len()
    + motor::PROTECTION.len()
    + cia402::AXIS_A.len()
    + CIA402_B.len()
    + MANUFACTURER_B.len()
    + RECORDS_B.len()
    + PROTECTION_B.len()
    + comm::MDP.len();

// Only used in const evaluation (the offsets, the initial image, the layout
// hash, the packed table) and packed once into OBJECTS.
#[allow(clippy::large_const_arrays)]
const TABLE: [Object; COUNT] = join(&[
    &comm::COMM,
    &MANUFACTURER_A,
    &records::PARAMS,
    &scope::PARAMS,
    &motor::PROTECTION,
    &cia402::AXIS_A,
    &CIA402_B,
    &MANUFACTURER_B,
    &RECORDS_B,
    &PROTECTION_B,
    &comm::MDP,
]);
const _: () = assert!(sorted(&TABLE), "objects must be sorted by index, each index once");
const _: () = assert!(entries_sorted(&TABLE), "entries must be sorted by subindex");
const _: () = assert!(
    defaults_in_range(&TABLE),
    "every default must be in its entry's range"
);

const fn defaults_in_range(objs: &[Object]) -> bool {
    let mut rest = objs;
    while let [o, tail @ ..] = rest {
        let mut es = declared(o.info.entries);
        while let [e, more @ ..] = es {
            if e.data_type.is_integer() && (e.default < e.lowest() || e.default > e.highest()) {
                return false;
            }
            es = more;
        }
        rest = tail;
    }
    true
}

/// Every object of the drive, sorted by index, its entries in [`ENTRY_TABLE`].
pub static OBJECTS: [Object; COUNT] = pack::objects(&TABLE, &ENTRY_TABLE);

const fn put(image: &mut [u8; IMAGE_BYTES], at: usize, v: i64, n: usize) {
    let b = v.to_le_bytes();
    let mut k = 0;
    while k < n && k < 8 {
        // at + k < IMAGE_BYTES by construction (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        {
            image[at + k] = b[k];
        }
        k += 1;
    }
}

/// The RAM image with every default, computed at compile time: the reference
/// for the image the dictionary writes at start (not in the firmware image).
pub const INITIAL_IMAGE: [u8; IMAGE_BYTES] = {
    let mut image = [0u8; IMAGE_BYTES];
    let offs = LAYOUT.0;
    let mut i = 0;
    while i < COUNT {
        // i < COUNT (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        let (o, mut at) = (&TABLE[i], offs[i] as usize);
        if o.declared_ram_bytes() > 0 {
            let mut rest = declared(o.info.entries);
            // the record memory (J410/J411 of either axis) starts with the
            // records' defaults
            let mut memory_at = 0;
            let memory = match o.info.index {
                i if i >= crate::AXIS_B_MANUFACTURER => i - crate::AXIS_B_MANUFACTURER,
                i => i,
            };
            while let [e, tail @ ..] = rest {
                if !e.data_type.is_string() {
                    put(&mut image, at, e.default, e.data_type.bytes());
                } else if matches!(memory, records::J410 | records::J411) {
                    let mut k = 0;
                    while k < e.data_type.bytes() {
                        if let Some(b) = records::initial_byte(memory, memory_at + k) {
                            // at + k < IMAGE_BYTES by construction
                            #[allow(clippy::indexing_slicing)]
                            {
                                image[at + k] = b;
                            }
                        }
                        k += 1;
                    }
                    memory_at += e.data_type.bytes();
                }
                at += e.data_type.bytes();
                rest = tail;
            }
        }
        i += 1;
    }
    image
};

/// The persistent entries in one walk of the table: FNV-1a over their
/// layout (index, subindex, type, size) and the bytes of their values.
const PERSISTENT_LAYOUT: (u32, usize) = {
    let mut h: u32 = 0x811C_9DC5;
    let mut n = 0;
    let mut i = 0;
    while i < COUNT {
        // i < COUNT (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        let o = &TABLE[i];
        if o.declared_ram_bytes() > 0 {
            let mut rest = declared(o.info.entries);
            while let [e, tail @ ..] = rest {
                if e.persistent {
                    let words = [
                        o.info.index as u32,
                        e.sub as u32,
                        e.data_type.code() as u32,
                        e.data_type.bytes() as u32,
                    ];
                    let mut w = 0;
                    while w < 4 {
                        #[allow(clippy::indexing_slicing)]
                        let b = words[w].to_le_bytes();
                        let mut k = 0;
                        while k < 4 {
                            #[allow(clippy::indexing_slicing)]
                            {
                                h ^= b[k] as u32;
                            }
                            h = h.wrapping_mul(0x0100_0193);
                            k += 1;
                        }
                        w += 1;
                    }
                    n += e.data_type.bytes();
                }
                rest = tail;
            }
        }
        i += 1;
    }
    (h, n)
};

/// FNV-1a over the layout of the persistent entries (index, subindex, type,
/// size): a saved image from another declaration has another hash.
pub const LAYOUT_HASH: u32 = PERSISTENT_LAYOUT.0;

/// Bytes of the persistent values (the payload of a saved image).
pub const PERSISTENT_BYTES: usize = PERSISTENT_LAYOUT.1;

/// The object at `index` and its position in [`OBJECTS`] (visible or not).
pub fn find(index: u16) -> Option<(usize, &'static Object)> {
    let i = OBJECTS.binary_search_by_key(&index, |o| o.info.index).ok()?;
    OBJECTS.get(i).map(|o| (i, o))
}

/// Allowed values of enumerated entries (axis-A index, SDO-Info subindex); a
/// value outside the list is refused with 0609 0030h. Axis-B objects use the
/// axis-A list.
pub const ENUMS: &[(u16, u8, &[i64])] = &[
    // 6060h modes of operation: -1 jog, 0 none, 1 pp, 2 vl, 3 pv, 4 pt, 6 hm,
    // 7 ip, 8 csp, 9 csv, 10 cst (od-cia402.md A-033)
    (0x6060, 0, &[-1, 0, 1, 2, 3, 4, 6, 7, 8, 9, 10]),
    // I425 speed feedforward interpolation (2 has no meaning, issue 40)
    (crate::params::I425, 0, &[0, 1, 3, 4, 5]),
    // 6098h homing method: the supported methods
    (0x6098, 0, &cia402::HOMING_METHODS_I64),
    // 605Ah quick stop option code (CiA 402: 0..8), 605Eh fault reaction (0..4)
    (0x605A, 0, &[0, 1, 2, 3, 4, 5, 6, 7, 8]),
    (0x605E, 0, &[0, 1, 2, 3, 4]),
    // A150 cycle time in µs (spec §12)
    (
        crate::parameter_index(0, 150),
        0,
        &[250, 500, 1000, 2000, 4000, 8000],
    ),
];

/// The enumeration of an entry, if it has one.
pub fn enumeration(index: u16, sub: u8) -> Option<&'static [i64]> {
    let a = match index {
        0x6800..=0x6DFF => index - crate::AXIS_B_CIA402,
        0xA000..=0xD3FF => index - crate::AXIS_B_MANUFACTURER,
        _ => index,
    };
    ENUMS
        .iter()
        .find(|(i, s, _)| *i == a && *s == sub)
        .map(|(_, _, v)| *v)
}
