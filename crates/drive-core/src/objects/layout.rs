//! The RAM image's layout, computed at compile time: where each object's
//! values lie ([`OFFSETS`]), the two axis blocks at its start
//! ([`AXIS_BLOCK`]), and the control cycle's entries at fixed places in
//! them ([`CycleField`], [`cycle`]).

use super::{declared, COUNT, TABLE};
use core::marker::PhantomData;
use od::DataType;

/// The objects of axis A's block, in order: its standard PDO layout
/// (spec §5.4: 1600h, then 1A00h, in mapping order) and then the other
/// entries the control cycle reads or writes every cycle ([`CYCLE_A`]).
/// The RAM image begins with this block for axis A and the same objects of
/// axis B after it ([`AXIS_BLOCK`] bytes each, the same order), then every
/// other object in table order. So:
/// - the values the standard layout maps are adjacent in the RAM image as
///   in the process image, and its copy programs ([`crate::pdo_image`])
///   move them as a few runs of 8 bytes rather than entry by entry (any
///   other mapping copies entry by entry);
/// - each cyclic entry of an axis lies at a compile-time offset in its
///   axis' block ([`CycleField`]), which the control cycle loads and
///   stores without a lookup, a bounds check or an `Option`.
const BLOCK_ORDER: [&[u16]; 3] = [
    &pdo_indices(&crate::pdo_maps::RX_A),
    &pdo_indices(&crate::pdo_maps::TX_A),
    &CYCLE_A,
];

/// The entries the control cycle reads or writes every cycle besides the
/// standard layout's (axis-A numbering): the ip set-point, the touch
/// probe, vl, I210, 6078h, and the switch-on-disabled causes and E80/E48.
pub(crate) const CYCLE_A: [u16; 16] = [
    0x60C1,
    0x60B8,
    0x6042,
    crate::params::I210,
    0x6078,
    0x60B9,
    0x60BA,
    0x60BB,
    0x60BC,
    0x60BD,
    0x6043,
    0x6044,
    crate::params::E80,
    crate::params::E48,
    crate::params::E47,
    crate::params::E49,
];

/// The indices of `entries` (for [`BLOCK_ORDER`]).
const fn pdo_indices<const N: usize>(entries: &[od::PdoEntry; N]) -> [u16; N] {
    let mut out = [0u16; N];
    let mut i = 0;
    while i < N {
        // i < N (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        {
            out[i] = entries[i].index;
        }
        i += 1;
    }
    out
}

/// Axis B's index of the per-axis object `index` (axis-A numbering): CiA 402
/// objects +800h, manufacturer parameters +8000h (`pdo_maps` numbers axis B's
/// PDO entries with it).
pub(crate) const fn axis_b_index(index: u16) -> u16 {
    if index >= 0x6000 {
        index.wrapping_add(crate::AXIS_B_CIA402)
    } else {
        index.wrapping_add(crate::AXIS_B_MANUFACTURER)
    }
}

/// Places the objects of [`BLOCK_ORDER`] (axis B's when `b`) from `at` on,
/// each once; returns where the block ends.
const fn place_block(out: &mut [u16; COUNT], placed: &mut [bool; COUNT], mut at: usize, b: bool) -> usize {
    let mut l = 0;
    while l < BLOCK_ORDER.len() {
        // l < BLOCK_ORDER.len() (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        let mut list = BLOCK_ORDER[l];
        while let [index, rest @ ..] = list {
            let index = *index;
            let i = table_position(if b { axis_b_index(index) } else { index });
            assert!(i < COUNT, "every object of an axis block is declared");
            // i < COUNT (asserted above; compile-time evaluation)
            #[allow(clippy::indexing_slicing)]
            if !placed[i] {
                placed[i] = true;
                out[i] = at as u16;
                at += TABLE[i].declared_ram_bytes();
            }
            list = rest;
        }
        l += 1;
    }
    at
}

const fn offsets() -> ([u16; COUNT], usize, usize) {
    let mut out = [0u16; COUNT];
    let mut placed = [false; COUNT];
    // first the two axis blocks, the same objects in the same order
    let block = place_block(&mut out, &mut placed, 0, false);
    let end = place_block(&mut out, &mut placed, block, true);
    assert!(end == 2 * block, "axis B's block is axis A's");
    // then every other object in table order
    let mut at = end;
    let mut i = 0;
    while i < COUNT {
        // i < COUNT (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        if !placed[i] {
            out[i] = at as u16;
            at += TABLE[i].declared_ram_bytes();
        }
        i += 1;
    }
    assert!(at <= u16::MAX as usize, "RAM image too large for u16 offsets");
    (out, at, block)
}

/// [`offsets`] evaluated once.
pub(crate) const LAYOUT: ([u16; COUNT], usize, usize) = offsets();

/// Bytes of one axis block at the start of the RAM image (axis A's at 0,
/// axis B's at `AXIS_BLOCK`): the objects of the axis' standard PDO layout, then
/// the other entries its control cycle reads or writes (`objects::cycle`).
pub const AXIS_BLOCK: usize = LAYOUT.2;

/// Size of the RAM image in bytes.
pub const IMAGE_BYTES: usize = LAYOUT.1;

/// Byte offset in the RAM image of the values of the object at `index`
/// (0 when it has none), computed at compile time.
pub const fn image_offset(index: u16) -> usize {
    let i = table_position(index);
    if i < COUNT {
        // i < COUNT (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        return LAYOUT.0[i] as usize;
    }
    0
}

/// Position of the object `index` in [`TABLE`] (`COUNT` when there is none),
/// for the compile-time layout.
const fn table_position(index: u16) -> usize {
    let mut i = 0;
    while i < COUNT {
        // i < COUNT (compile-time evaluation)
        #[allow(clippy::indexing_slicing)]
        if TABLE[i].info.index == index {
            return i;
        }
        i += 1;
    }
    COUNT
}

/// Byte offset of each object's values in the RAM image (objects with
/// [`Value::Ram`](super::Value::Ram) / [`Value::Live`](super::Value::Live); entries follow each other in subindex
/// order, each [`DataType::bytes`] long).
pub static OFFSETS: [u16; COUNT] = LAYOUT.0;

/// A cyclic entry at a fixed place in its axis' block: its byte offset in
/// the block (the same for both axes, checked at compile time) and the Rust
/// type of its value. The control cycle's loads and stores
/// ([`crate::DriveObjects`]' `cycle_read`/`cycle_write`) use it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CycleField<T> {
    pub(crate) at: usize,
    value: PhantomData<T>,
}

impl<T> CycleField<T> {
    /// Byte offset of the value in its axis' block.
    pub const fn at(self) -> usize {
        self.at
    }
}

/// Whether `a` and `b` are the same integer type (compile-time `==`).
const fn same_integer(a: DataType, b: DataType) -> bool {
    matches!(
        (a, b),
        (DataType::Bool, DataType::Bool)
            | (DataType::I8, DataType::I8)
            | (DataType::I16, DataType::I16)
            | (DataType::I32, DataType::I32)
            | (DataType::U8, DataType::U8)
            | (DataType::U16, DataType::U16)
            | (DataType::U32, DataType::U32)
    )
}

/// Byte offset of `index`:`sub`'s value in the RAM image when it is declared
/// there as a `kind`; `None` otherwise.
const fn entry_offset(index: u16, sub: u8, kind: DataType) -> Option<usize> {
    let i = table_position(index);
    if i >= COUNT {
        return None;
    }
    // i < COUNT (compile-time evaluation)
    #[allow(clippy::indexing_slicing)]
    let (o, mut at) = (&TABLE[i], LAYOUT.0[i] as usize);
    if o.declared_ram_bytes() == 0 {
        return None;
    }
    let mut rest = declared(o.info.entries);
    while let [e, tail @ ..] = rest {
        if e.sub == sub {
            return if same_integer(e.data_type, kind) {
                Some(at)
            } else {
                None
            };
        }
        at += e.data_type.bytes();
        rest = tail;
    }
    None
}

/// The field of `index`:`sub` (axis-A numbering) of type `kind`, which must
/// be `T`'s width; a compile error unless the entry lies in axis A's block
/// as a `kind` and axis B's entry at the same place in axis B's block.
const fn field<T>(index: u16, sub: u8, kind: DataType) -> CycleField<T> {
    assert!(
        kind.bytes() == core::mem::size_of::<T>(),
        "the field's type has the entry's width"
    );
    let (a, b) = match (
        entry_offset(index, sub, kind),
        entry_offset(axis_b_index(index), sub, kind),
    ) {
        (Some(a), Some(b)) => (a, b),
        _ => (usize::MAX, 0),
    };
    assert!(
        a != usize::MAX,
        "a cycle field is an integer entry in RAM on both axes"
    );
    assert!(
        a + kind.bytes() <= AXIS_BLOCK,
        "a cycle field lies in axis A's block"
    );
    assert!(
        b == a + AXIS_BLOCK,
        "axis B's field lies at the same place in its block"
    );
    CycleField {
        at: a,
        value: PhantomData,
    }
}

/// The control cycle's entries in the axis blocks (axis-A numbering; the
/// same offsets in axis B's block): the set-points it reads and the actual
/// values it writes every cycle.
pub(crate) mod cycle {
    use super::{field, CycleField};
    use crate::params::{A67, E47, E48, E49, E80, I210 as I210_INDEX};
    use od::DataType::{I16, I32, I8, U16, U32, U8};

    pub const CONTROLWORD: CycleField<u16> = field(0x6040, 0, U16);
    pub const MODE: CycleField<i8> = field(0x6060, 0, I8);
    pub const TARGET_POSITION: CycleField<i32> = field(0x607A, 0, I32);
    pub const IP_SETPOINT: CycleField<i32> = field(0x60C1, 1, I32);
    pub const TARGET_VELOCITY: CycleField<i32> = field(0x60FF, 0, I32);
    pub const TARGET_TORQUE: CycleField<i16> = field(0x6071, 0, I16);
    pub const VELOCITY_OFFSET: CycleField<i32> = field(0x60B1, 0, I32);
    pub const TORQUE_OFFSET: CycleField<i16> = field(0x60B2, 0, I16);
    pub const PROBE_FUNCTION: CycleField<u16> = field(0x60B8, 0, U16);
    pub const VL_TARGET: CycleField<i16> = field(0x6042, 0, I16);
    pub const I210: CycleField<u16> = field(I210_INDEX, 0, U16);
    pub const STATUSWORD: CycleField<u16> = field(0x6041, 0, U16);
    pub const MODE_DISPLAY: CycleField<i8> = field(0x6061, 0, I8);
    pub const POSITION: CycleField<i32> = field(0x6064, 0, I32);
    pub const VELOCITY: CycleField<i32> = field(0x606C, 0, I32);
    pub const TORQUE: CycleField<i16> = field(0x6077, 0, I16);
    pub const CURRENT: CycleField<i16> = field(0x6078, 0, I16);
    pub const FOLLOWING_ERROR: CycleField<i32> = field(0x60F4, 0, I32);
    pub const PROBE_STATUS: CycleField<u16> = field(0x60B9, 0, U16);
    pub const PROBE_VALUES: [CycleField<i32>; 4] = [
        field(0x60BA, 0, I32),
        field(0x60BB, 0, I32),
        field(0x60BC, 0, I32),
        field(0x60BD, 0, I32),
    ];
    pub const ADDITIONAL_POSITION: CycleField<i32> = field(0x60E4, 1, I32);
    pub const VL_DEMAND: CycleField<i16> = field(0x6043, 0, I16);
    pub const VL_ACTUAL: CycleField<i16> = field(0x6044, 0, I16);
    pub const DIGITAL_INPUTS: CycleField<u32> = field(0x60FD, 0, U32);
    pub const E80_FIELD: CycleField<u8> = field(E80, 0, U8);
    pub const E48_FIELD: CycleField<u8> = field(E48, 0, U8);
    pub const E47_FIELD: CycleField<u8> = field(E47, 0, U8);
    pub const E49_FIELD: CycleField<u8> = field(E49, 0, U8);
    pub const A67_FIELD: CycleField<u16> = field(A67, 0, U16);
}

/// A run of the standard PDO layout of one axis: `len` bytes that lie at
/// `ram` in the axis' block and at `img` in the axis' part of the process
/// image, entries adjacent in both.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Run {
    pub ram: usize,
    pub img: usize,
    pub len: usize,
}

/// The two runs of `entries` (axis A's standard RxPDO or TxPDO) in the axis
/// block, and the bytes of the axis' image; a compile error unless there are
/// exactly two runs.
const fn two_runs(entries: &[od::PdoEntry]) -> (Run, Run, usize) {
    let empty = Run {
        ram: 0,
        img: 0,
        len: 0,
    };
    let (mut first, mut second, mut count) = (empty, empty, 0);
    let mut img = 0;
    let mut rest = entries;
    while let [e, tail @ ..] = rest {
        let n = e.data_type.bytes();
        let ram = match entry_offset(e.index, e.sub, e.data_type) {
            Some(at) => at,
            None => usize::MAX,
        };
        assert!(
            ram != usize::MAX && ram + n <= AXIS_BLOCK,
            "a standard entry lies in axis A's block"
        );
        let open = if count == 1 { first } else { second };
        if count > 0 && open.ram + open.len == ram && open.img + open.len == img {
            if count == 1 {
                first.len += n;
            } else {
                second.len += n;
            }
        } else {
            count += 1;
            let run = Run { ram, img, len: n };
            if count == 1 {
                first = run;
            } else {
                second = run;
            }
        }
        img += n;
        rest = tail;
    }
    assert!(
        count == 2,
        "the standard layout of an axis is two runs in its block"
    );
    (first, second, img)
}

/// Axis A's standard RxPDO (1600h's default) in its block: 6040h … 6071h
/// and 60FEh:01 (60FEh's count lies between them in RAM), and its bytes.
pub(crate) const RX_RUNS: (Run, Run, usize) = two_runs(&crate::pdo_maps::RX_A);

/// Axis A's standard TxPDO (1A00h's default) in its block: 6041h … 60FDh
/// and 60E4h:01 … A67 (60E4h's count between them), and its bytes.
pub(crate) const TX_RUNS: (Run, Run, usize) = two_runs(&crate::pdo_maps::TX_A);
