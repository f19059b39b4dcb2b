//! The alarm blocks of a DATA-RTA-PDU: AlarmNotification (device →
//! controller) and AlarmAck (controller → device), with the AlarmSpecifier,
//! ChannelProperties and the extended channel diagnosis item.
//!
//! ```text
//! AlarmNotification: BlockHeader (type 0x0001 high / 0x0002 low, length,
//!   version 1.0) | AlarmType (2) | API (4) | SlotNumber (2) | SubslotNumber (2)
//!   | ModuleIdentNumber (4) | SubmoduleIdentNumber (4) | AlarmSpecifier (2)
//!   [ | USI 0x8002 (2) | ChannelNumber (2) | ChannelProperties (2)
//!   | ChannelErrorType (2) | ExtChannelErrorType (2) | ExtChannelAddValue (4) ]
//! AlarmAck: BlockHeader (type 0x8001 / 0x8002, length 18, version 1.0)
//!   | AlarmType | API | SlotNumber | SubslotNumber | AlarmSpecifier | PNIOStatus (4)
//! ```
//!
//! One diagnosis item per notification: that is what every controller reads
//! (profinet-py parses one USI per item).

use super::{PnioStatus, Priority};

/// AlarmType values.
pub struct AlarmType;

impl AlarmType {
    /// Diagnosis (appears, or disappears while others remain).
    pub const DIAGNOSIS: u16 = 0x0001;
    /// Process.
    pub const PROCESS: u16 = 0x0002;
    /// Pull.
    pub const PULL: u16 = 0x0003;
    /// Plug.
    pub const PLUG: u16 = 0x0004;
    /// Diagnosis disappears (the last diagnosis of the submodule went).
    pub const DIAGNOSIS_DISAPPEARS: u16 = 0x000C;
}

/// USI of the extended channel diagnosis.
pub const USI_EXT_CHANNEL_DIAGNOSIS: u16 = 0x8002;
/// ChannelNumber for the whole submodule.
pub const CHANNEL_SUBMODULE: u16 = 0x8000;
/// Length of an AlarmNotification without an item.
pub const NOTIFICATION_LEN: usize = 26;
/// Length of the USI and one extended channel diagnosis item.
pub const ITEM_LEN: usize = 14;
/// Length of an AlarmAck block.
pub const ACK_LEN: usize = 22;

/// AlarmSpecifier: SequenceNumber bits 0…10, ChannelDiagnosis bit 11,
/// ManufacturerSpecificDiagnosis bit 12, SubmoduleDiagnosisState bit 13,
/// ARDiagnosisState bit 15.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AlarmSpecifier(pub u16);

impl AlarmSpecifier {
    /// The flags (sequence number 0).
    pub const fn new(
        channel_diagnosis: bool,
        manufacturer: bool,
        submodule_diagnosis: bool,
        ar_diagnosis: bool,
    ) -> AlarmSpecifier {
        AlarmSpecifier(
            (channel_diagnosis as u16) << 11
                | (manufacturer as u16) << 12
                | (submodule_diagnosis as u16) << 13
                | (ar_diagnosis as u16) << 15,
        )
    }
    /// With the sequence number `seq` (11 bits).
    pub const fn with_sequence(self, seq: u16) -> AlarmSpecifier {
        AlarmSpecifier((self.0 & !0x07FF) | (seq & 0x07FF))
    }
    /// SequenceNumber.
    pub const fn sequence(self) -> u16 {
        self.0 & 0x07FF
    }
    /// ChannelDiagnosis: channel diagnosis exists on the submodule.
    pub const fn channel_diagnosis(self) -> bool {
        self.0 & 0x0800 != 0
    }
    /// ManufacturerSpecificDiagnosis.
    pub const fn manufacturer(self) -> bool {
        self.0 & 0x1000 != 0
    }
    /// SubmoduleDiagnosisState: the submodule has diagnosis.
    pub const fn submodule_diagnosis(self) -> bool {
        self.0 & 0x2000 != 0
    }
    /// ARDiagnosisState: some submodule of the AR has diagnosis.
    pub const fn ar_diagnosis(self) -> bool {
        self.0 & 0x8000 != 0
    }
}

/// ChannelProperties.Specifier (bits 11…12).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Specifier {
    /// All subsequent disappears.
    AllDisappear = 0,
    /// Appears.
    Appears = 1,
    /// Disappears.
    Disappears = 2,
    /// Disappears but others remain.
    DisappearsOthersRemain = 3,
}

/// ChannelProperties.Maintenance (bits 9…10): the severity.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Maintenance {
    /// Fault (a drive error).
    Fault = 0,
    /// Maintenance required (a warning).
    Required = 1,
    /// Maintenance demanded.
    Demanded = 2,
}

/// ChannelProperties.Direction (bits 13…15).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ChannelDirection {
    /// Manufacturer specific.
    Manufacturer = 0,
    /// Input.
    Input = 1,
    /// Output.
    Output = 2,
    /// Input and output.
    InputOutput = 3,
}

/// ChannelProperties: Type bits 0…7, Accumulative bit 8, Maintenance bits
/// 9…10, Specifier bits 11…12, Direction bits 13…15.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ChannelProperties(pub u16);

impl ChannelProperties {
    /// Built from its fields.
    pub const fn new(
        channel_type: u8,
        accumulative: bool,
        maintenance: Maintenance,
        specifier: Specifier,
        direction: ChannelDirection,
    ) -> ChannelProperties {
        ChannelProperties(
            channel_type as u16
                | (accumulative as u16) << 8
                | (maintenance as u16) << 9
                | (specifier as u16) << 11
                | (direction as u16) << 13,
        )
    }
    /// Type (0: submodule / unspecified).
    pub const fn channel_type(self) -> u8 {
        (self.0 & 0xFF) as u8
    }
    /// Accumulative.
    pub const fn accumulative(self) -> bool {
        self.0 & 0x0100 != 0
    }
    /// The maintenance bits.
    pub const fn maintenance_bits(self) -> u16 {
        (self.0 >> 9) & 3
    }
    /// The specifier bits.
    pub const fn specifier_bits(self) -> u16 {
        (self.0 >> 11) & 3
    }
    /// The direction bits.
    pub const fn direction_bits(self) -> u16 {
        self.0 >> 13
    }
    /// The same with another specifier.
    pub const fn with_specifier(self, s: Specifier) -> ChannelProperties {
        ChannelProperties((self.0 & !0x1800) | (s as u16) << 11)
    }
}

/// One extended channel diagnosis item (USI 0x8002).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DiagItem {
    /// ChannelNumber (0x8000: the submodule).
    pub channel: u16,
    /// ChannelProperties.
    pub properties: ChannelProperties,
    /// ChannelErrorType.
    pub error_type: u16,
    /// ExtChannelErrorType.
    pub ext_error_type: u16,
    /// ExtChannelAddValue.
    pub add_value: u32,
}

impl DiagItem {
    /// Writes ChannelNumber … ExtChannelAddValue (12 bytes, no USI).
    pub(crate) fn write(&self, w: &mut Writer<'_>) -> Option<()> {
        w.u16(self.channel)?;
        w.u16(self.properties.0)?;
        w.u16(self.error_type)?;
        w.u16(self.ext_error_type)?;
        w.u32(self.add_value)
    }
}

/// An AlarmNotification.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Notification {
    /// Its priority (block type and channel).
    pub priority: Priority,
    /// AlarmType.
    pub alarm_type: u16,
    /// API.
    pub api: u32,
    /// SlotNumber.
    pub slot: u16,
    /// SubslotNumber.
    pub subslot: u16,
    /// ModuleIdentNumber.
    pub module_ident: u32,
    /// SubmoduleIdentNumber.
    pub submodule_ident: u32,
    /// AlarmSpecifier (the alarm CR sets the sequence number).
    pub specifier: AlarmSpecifier,
    /// The diagnosis item, if any.
    pub item: Option<DiagItem>,
}

impl Notification {
    /// Its length in bytes.
    pub const fn len(&self) -> usize {
        NOTIFICATION_LEN + if self.item.is_some() { ITEM_LEN } else { 0 }
    }

    /// Never empty.
    pub const fn is_empty(&self) -> bool {
        false
    }

    /// Writes the block; `None` if `buf` is shorter than [`Notification::len`].
    pub fn emit(&self, buf: &mut [u8]) -> Option<usize> {
        let len = self.len();
        let mut w = Writer::new(buf.get_mut(..len)?);
        w.block_header(self.priority.notification_block(), len, 0)?;
        w.u16(self.alarm_type)?;
        w.u32(self.api)?;
        w.u16(self.slot)?;
        w.u16(self.subslot)?;
        w.u32(self.module_ident)?;
        w.u32(self.submodule_ident)?;
        w.u16(self.specifier.0)?;
        if let Some(item) = &self.item {
            w.u16(USI_EXT_CHANNEL_DIAGNOSIS)?;
            item.write(&mut w)?;
        }
        Some(w.pos)
    }
}

/// An AlarmAck.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AlarmAck {
    /// Its priority (from the block type).
    pub priority: Priority,
    /// AlarmType of the acknowledged alarm.
    pub alarm_type: u16,
    /// API.
    pub api: u32,
    /// SlotNumber.
    pub slot: u16,
    /// SubslotNumber.
    pub subslot: u16,
    /// AlarmSpecifier (its sequence number names the alarm).
    pub specifier: AlarmSpecifier,
    /// PNIOStatus (OK, or why the controller refused the alarm).
    pub status: PnioStatus,
}

impl AlarmAck {
    /// Parses an AlarmAck block; `None` if it is none (other block type,
    /// version or length) or truncated.
    pub fn parse(b: &[u8]) -> Option<AlarmAck> {
        let b: &[u8; ACK_LEN] = b.get(..ACK_LEN)?.try_into().ok()?;
        let [t0, t1, l0, l1, vh, _vl, a0, a1, p0, p1, p2, p3, s0, s1, u0, u1, c0, c1, e0, e1, e2, e3] = *b;
        let priority = match u16::from_be_bytes([t0, t1]) {
            0x8001 => Priority::High,
            0x8002 => Priority::Low,
            _ => return None,
        };
        if u16::from_be_bytes([l0, l1]) != (ACK_LEN - 4) as u16 || vh != 1 {
            return None;
        }
        Some(AlarmAck {
            priority,
            alarm_type: u16::from_be_bytes([a0, a1]),
            api: u32::from_be_bytes([p0, p1, p2, p3]),
            slot: u16::from_be_bytes([s0, s1]),
            subslot: u16::from_be_bytes([u0, u1]),
            specifier: AlarmSpecifier(u16::from_be_bytes([c0, c1])),
            status: PnioStatus([e0, e1, e2, e3]),
        })
    }

    /// Writes the block (22 bytes); `None` if `buf` is shorter.
    pub fn emit(&self, buf: &mut [u8]) -> Option<usize> {
        let mut w = Writer::new(buf.get_mut(..ACK_LEN)?);
        w.block_header(self.priority.ack_block(), ACK_LEN, 0)?;
        w.u16(self.alarm_type)?;
        w.u32(self.api)?;
        w.u16(self.slot)?;
        w.u16(self.subslot)?;
        w.u16(self.specifier.0)?;
        w.bytes(&self.status.0)?;
        Some(w.pos)
    }

    /// It acknowledges `n` (priority, type, location, sequence number).
    pub fn matches(&self, n: &Notification) -> bool {
        self.priority == n.priority
            && self.alarm_type == n.alarm_type
            && self.api == n.api
            && self.slot == n.slot
            && self.subslot == n.subslot
            && self.specifier.sequence() == n.specifier.sequence()
    }
}

/// A bounded big-endian writer: every call fails (`None`) instead of
/// writing past the end.
pub(crate) struct Writer<'a> {
    buf: &'a mut [u8],
    pub(crate) pos: usize,
}

impl<'a> Writer<'a> {
    pub(crate) fn new(buf: &'a mut [u8]) -> Writer<'a> {
        Writer { buf, pos: 0 }
    }
    pub(crate) fn bytes(&mut self, b: &[u8]) -> Option<()> {
        let end = self.pos.checked_add(b.len())?;
        self.buf.get_mut(self.pos..end)?.copy_from_slice(b);
        self.pos = end;
        Some(())
    }
    pub(crate) fn u16(&mut self, v: u16) -> Option<()> {
        self.bytes(&v.to_be_bytes())
    }
    pub(crate) fn u32(&mut self, v: u32) -> Option<()> {
        self.bytes(&v.to_be_bytes())
    }
    /// BlockHeader of a block of `len` bytes in all, version 1.`low`.
    pub(crate) fn block_header(&mut self, block_type: u16, len: usize, low: u8) -> Option<()> {
        self.u16(block_type)?;
        self.u16(u16::try_from(len.checked_sub(4)?).ok()?)?;
        self.bytes(&[1, low])
    }
    /// Overwrites a u16 at `at` (a block length known only at the end).
    pub(crate) fn patch_u16(&mut self, at: usize, v: u16) -> Option<()> {
        self.buf.get_mut(at..at + 2)?.copy_from_slice(&v.to_be_bytes());
        Some(())
    }
}
