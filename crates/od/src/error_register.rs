//! The CiA 301 error register (1001h) bits, as emergencies and the CiA 402
//! error code (603Fh) of a fault carry them.

/// Bit 0: generic error.
pub const GENERIC: u8 = 0x01;
/// Bit 1: current.
pub const CURRENT: u8 = 0x02;
/// Bit 2: voltage.
pub const VOLTAGE: u8 = 0x04;
/// Bit 3: temperature.
pub const TEMPERATURE: u8 = 0x08;
/// Bit 4: communication.
pub const COMMUNICATION: u8 = 0x10;
