//! The scope's objects (group T "Scope", issue 35): the manual's parameter
//! map reserves 4600h–47FFh for it (T lines at `parameter_index(19, line)` =
//! 4600h + line) but the seeds name no T parameter, so every line here is
//! assumed (each note says so). Global (one recorder for the device; a
//! channel names either axis' entries).
//!
//! Their values are the recorder's ([`crate::scope::Recorder`] as the
//! [`crate::LiveValues`] provider, [`Value::Provided`]): no RAM image bytes,
//! not saved; a drive without a recorder answers 0800 0022h.

use super::{Object, Value};
use crate::params::{T00, T01, T02, T03, T04, T05, T06, T07, T08, T09, T10, T11};
use crate::scope::{BLOCKS, BLOCK_BYTES, MAX_CHANNELS};
use od::DataType::{OctetString, I32, U16, U32, U8};
use od::{Access, DataType, EntryInfo};

const fn e(sub: u8, name: &'static str, t: DataType) -> EntryInfo {
    EntryInfo::new(sub, name, t, Access::RW)
}

const fn ro(sub: u8, name: &'static str, t: DataType) -> EntryInfo {
    EntryInfo::new(sub, name, t, Access::RO)
}

const CHANNEL_NAMES: [&str; MAX_CHANNELS] = numbered!("Channel "; 1 2 3 4 5 6 7 8);
const CHANNELS: [EntryInfo; MAX_CHANNELS] = super::repeat(e(0, "", U32), 0, &CHANNEL_NAMES);
const BLOCK_NAMES: [&str; BLOCKS as usize] = numbered!("Block "; 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16);
const DATA: [EntryInfo; BLOCKS as usize] =
    super::repeat(ro(0, "", OctetString(BLOCK_BYTES as u16)), 0, &BLOCK_NAMES);

/// The scope's objects, sorted by index.
pub const PARAMS: [Object; 12] = [
    Object::var(T00, Value::Provided, entries![e(0, "Scope state", U8).range(0, 3)])
        .level(1)
        .note("T00 (line assumed): the recorder's state, 0 idle, 1 armed, 2 triggered, 3 complete; a write of 1 arms a trace with T01…T09 (refused 0609 0030h without channels or with an unset one among channels 1…T02, 0609 0031h when T04 × T02 exceeds the buffer), 0 stops (the trace is gone); 2 and 3 are refused (0609 0030h)"),
    param_array!(T01, "Scope channels", Array, Value::Provided, from &CHANNELS)
        .level(1)
        .note("T01 (line assumed): what channels 1…8 record, as a PDO mapping entry (index << 16 | subindex << 8 | bit length; \"EtherCAT Rx SDO Info\" numbering) of a PDO-mappable integer entry (else 0604 0041h; a wrong bit length 0604 0043h), or an internal signal: index 0, subindex axis·10h + n, 32 bits, n = 1 speed set-point (inc/s), 2 speed actual value (inc/s), 3 following error (inc), 4 iq (mA), 5 id (mA), 6 ud (mV) as the current loop reports them (uq is not reported); 0 = off. Writes while armed or triggered: 0800 0022h"),
    Object::var(T02, Value::Provided, entries![e(0, "Scope channel count", U8)])
        .level(1)
        .note("T02 (line assumed): channels 1…T02 are recorded; above 8: 0609 0031h (checked by the recorder: the packed table has no room for another range)"),
    Object::var(T03, Value::Provided, entries![e(0, "Scope divider", U16).default_value(1)])
        .level(1)
        .note("T03 (line assumed): one sample every T03 control cycles (A150), 1…1000 (0: 0609 0032h, above: 0609 0031h); default 1"),
    Object::var(T04, Value::Provided, entries![e(0, "Scope length", U32)])
        .level(1)
        .note("T04 (line assumed): samples per channel; 0 = as many as the buffer holds (at most 16 × 4096 bytes, T11); T04 × T02 beyond the buffer: 0609 0031h"),
    Object::var(T05, Value::Provided, entries![e(0, "Scope trigger source", U16)])
        .level(1)
        .note("T05 (line assumed): 0 none (the trace triggers as soon as the pre-trigger share is recorded), 1…8 the value of channel k, 10h + n statusword bit n of axis A (6041h), 20h + n of axis B (6841h); other values 0609 0030h"),
    Object::var(T06, Value::Provided, entries![e(0, "Scope trigger condition", U8).range(0, 4)])
        .level(1)
        .note("T06 (line assumed): 0 value ≥ T07, 1 value < T07, 2 rising edge (from below T07 to at or above it), 3 falling edge, 4 either edge; a statusword bit's value is 0 or 1 against the level 1"),
    Object::var(T07, Value::Provided, entries![e(0, "Scope trigger level", I32)])
        .level(1)
        .note("T07 (line assumed): the trigger level in the source channel's unit"),
    Object::var(T08, Value::Provided, entries![e(0, "Scope pre-trigger", U8).range(0, 100).unit("%")])
        .level(1)
        .note("T08 (line assumed): the share of the trace before the trigger; the trigger sample is sample ⌊T04·T08/100⌋ of the trace"),
    Object::var(T09, Value::Provided, entries![e(0, "Scope mode", U8).range(0, 1)])
        .level(1)
        .note("T09 (line assumed): 0 single (a complete trace stays until armed again), 1 normal (the recorder arms itself again once the trace's last block of T11 is read)"),
    param_array!(T10, "Scope trace information", Record, Value::Provided, [
        ro(0, "Samples per channel", U32),
        ro(1, "Trigger index", U32),
        ro(2, "Completed traces", U32),
        ro(3, "Buffer words", U32),
    ])
    .level(1)
    .note("T10 (line assumed): [0] samples per channel of the complete trace (0 before), [1] the trigger sample's index in it, [2] the traces completed since start (a new trace is a new number), [3] the words (32 bits) of the recorder's buffer"),
    param_array!(T11, "Scope trace data", Array, Value::Provided, from &DATA)
        .level(1)
        .note("T11 (line assumed): the complete trace, element k = its bytes 4096·k… (segmented SDO upload): sample by sample, channel by channel, each an INTEGER32 little-endian; only a complete trace is read (else 0800 0022h, never the last trace as new), beyond its end 0800 0024h"),
];
