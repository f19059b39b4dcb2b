//! SDO abort codes.

/// SDO abort code (CiA 301, spec §6.5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct SdoAbort(pub u32);

impl SdoAbort {
    /// 0503 0000h Toggle bit not alternated.
    pub const TOGGLE_BIT: Self = Self(0x0503_0000);
    /// 0504 0000h SDO protocol timed out.
    pub const TIMEOUT: Self = Self(0x0504_0000);
    /// 0504 0001h Command specifier invalid or unknown.
    pub const INVALID_COMMAND: Self = Self(0x0504_0001);
    /// 0504 0005h Out of memory.
    pub const OUT_OF_MEMORY: Self = Self(0x0504_0005);
    /// 0601 0000h Unsupported access to an object.
    pub const UNSUPPORTED_ACCESS: Self = Self(0x0601_0000);
    /// 0601 0001h Read of a write-only object.
    pub const WRITE_ONLY: Self = Self(0x0601_0001);
    /// 0601 0002h Write of a read-only object.
    pub const READ_ONLY: Self = Self(0x0601_0002);
    /// 0602 0000h Object does not exist in the object dictionary.
    pub const NO_OBJECT: Self = Self(0x0602_0000);
    /// 0604 0041h Object cannot be mapped into a PDO.
    pub const NOT_MAPPABLE: Self = Self(0x0604_0041);
    /// 0604 0042h Number/length of mapped objects exceeds the PDO length.
    pub const PDO_LENGTH: Self = Self(0x0604_0042);
    /// 0604 0043h General parameter incompatibility.
    pub const PARAMETER_INCOMPATIBLE: Self = Self(0x0604_0043);
    /// 0604 0047h General internal device incompatibility.
    pub const DEVICE_INCOMPATIBLE: Self = Self(0x0604_0047);
    /// 0606 0000h Access failed due to a hardware error.
    pub const HARDWARE_ERROR: Self = Self(0x0606_0000);
    /// 0607 0010h Data type / parameter length does not match.
    pub const TYPE_MISMATCH: Self = Self(0x0607_0010);
    /// 0607 0012h Data type mismatch, length too high.
    pub const LENGTH_TOO_HIGH: Self = Self(0x0607_0012);
    /// 0607 0013h Data type mismatch, length too low.
    pub const LENGTH_TOO_LOW: Self = Self(0x0607_0013);
    /// 0609 0011h Subindex does not exist.
    pub const NO_SUBINDEX: Self = Self(0x0609_0011);
    /// 0609 0030h Invalid value (write).
    pub const INVALID_VALUE: Self = Self(0x0609_0030);
    /// 0609 0031h Value too high.
    pub const VALUE_TOO_HIGH: Self = Self(0x0609_0031);
    /// 0609 0032h Value too low.
    pub const VALUE_TOO_LOW: Self = Self(0x0609_0032);
    /// 0609 0036h Maximum value below minimum value.
    pub const MAX_BELOW_MIN: Self = Self(0x0609_0036);
    /// 0800 0000h General error.
    pub const GENERAL: Self = Self(0x0800_0000);
    /// 0800 0020h Data cannot be transferred or stored.
    pub const TRANSFER: Self = Self(0x0800_0020);
    /// 0800 0021h ... because of local control.
    pub const LOCAL_CONTROL: Self = Self(0x0800_0021);
    /// 0800 0022h ... because of the present device state.
    pub const DEVICE_STATE: Self = Self(0x0800_0022);
    /// 0800 0023h Object dictionary not present / dynamic generation failed.
    pub const NO_DICTIONARY: Self = Self(0x0800_0023);
    /// 0800 0024h No data available.
    pub const NO_DATA: Self = Self(0x0800_0024);
}
