//! PNIO status (ErrorCode, ErrorDecode, ErrorCode1, ErrorCode2): the four
//! octets every refusal of the CM maps onto, one-to-one.

/// A PNIO status. All zero = OK.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct PnioStatus {
    /// ErrorCode: the service ([`error_code`]).
    pub code: u8,
    /// ErrorDecode: [`error_decode::PNIORW`] or [`error_decode::PNIO`].
    pub decode: u8,
    /// ErrorCode1: the block (PNIO) or error class/code (PNIORW).
    pub code1: u8,
    /// ErrorCode2: the faulty field of the block (PNIO), 0 for PNIORW.
    pub code2: u8,
}

/// ErrorCode values (the service the error belongs to).
pub mod error_code {
    /// Connect response.
    pub const IOD_CONNECT_RES: u8 = 0xDB;
    /// Release response.
    pub const IOD_RELEASE_RES: u8 = 0xDC;
    /// Control response.
    pub const IOD_CONTROL_RES: u8 = 0xDD;
    /// Read response.
    pub const IOD_READ_RES: u8 = 0xDE;
    /// Write response.
    pub const IOD_WRITE_RES: u8 = 0xDF;
}

/// ErrorDecode values.
pub mod error_decode {
    /// Record access (ErrorCode1 = class << 4 | code).
    pub const PNIORW: u8 = 0x80;
    /// Context management (ErrorCode1 = block, ErrorCode2 = field).
    pub const PNIO: u8 = 0x81;
}

/// ErrorCode1 values with ErrorDecode PNIO.
pub mod error_code1 {
    /// Connect: faulty ARBlockReq.
    pub const AR_BLOCK_REQ: u8 = 0x01;
    /// Connect: faulty IOCRBlockReq.
    pub const IOCR_BLOCK_REQ: u8 = 0x02;
    /// Connect: faulty ExpectedSubmoduleBlockReq.
    pub const EXPECTED_SUBMODULE_BLOCK_REQ: u8 = 0x03;
    /// Connect: faulty AlarmCRBlockReq.
    pub const ALARM_CR_BLOCK_REQ: u8 = 0x04;
    /// Read/Write: faulty record header.
    pub const RECORD: u8 = 0x08;
    /// Control: faulty IODControlReq (PrmEnd).
    pub const CONTROL_BLOCK_CONNECT: u8 = 0x14;
    /// Release: faulty IODReleaseReq.
    pub const RELEASE_BLOCK: u8 = 0x28;
    /// CMRPC (called RMPM by some tools); ErrorCode2 from [`super::cmrpc`].
    pub const CMRPC: u8 = 0x40;
}

/// ErrorCode2 values with ErrorCode1 [`error_code1::CMRPC`].
pub mod cmrpc {
    /// ArgsLength (NDR header) invalid.
    pub const ARGS_LENGTH_INVALID: u8 = 0;
    /// Unknown block type.
    pub const UNKNOWN_BLOCKS: u8 = 1;
    /// IOCR missing.
    pub const IOCR_MISSING: u8 = 2;
    /// Wrong number of AlarmCRBlockReq.
    pub const WRONG_ALARM_CR_COUNT: u8 = 3;
    /// Out of AR resources (another AR holds the device).
    pub const OUT_OF_AR_RESOURCES: u8 = 4;
    /// AR UUID unknown.
    pub const AR_UUID_UNKNOWN: u8 = 5;
    /// State conflict (e.g. PrmEnd twice).
    pub const STATE_CONFLICT: u8 = 6;
    /// Out of provider, consumer or alarm resources (too many objects).
    pub const OUT_OF_RESOURCES: u8 = 7;
}

impl PnioStatus {
    /// Success.
    pub const OK: PnioStatus = PnioStatus {
        code: 0,
        decode: 0,
        code1: 0,
        code2: 0,
    };

    /// A PNIO (context management) error of service `code`: block `code1`, field `code2`.
    pub const fn pnio(code: u8, code1: u8, code2: u8) -> PnioStatus {
        PnioStatus {
            code,
            decode: error_decode::PNIO,
            code1,
            code2,
        }
    }

    /// A faulty field `field` of Connect block `block` ([`error_code1`]).
    pub const fn connect(block: u8, field: u8) -> PnioStatus {
        PnioStatus::pnio(error_code::IOD_CONNECT_RES, block, field)
    }

    /// A CMRPC error ([`cmrpc`]) of service `code`.
    pub const fn cmrpc(code: u8, code2: u8) -> PnioStatus {
        PnioStatus::pnio(code, error_code1::CMRPC, code2)
    }

    /// A record access error of service `code` (read or write).
    pub const fn rw(code: u8, code1: u8) -> PnioStatus {
        PnioStatus {
            code,
            decode: error_decode::PNIORW,
            code1,
            code2: 0,
        }
    }

    /// True for OK.
    pub const fn is_ok(self) -> bool {
        self.code == 0 && self.decode == 0 && self.code1 == 0 && self.code2 == 0
    }

    /// As the 32-bit value of the NDR header (ErrorCode most significant),
    /// written in the call's byte order.
    pub const fn to_u32(self) -> u32 {
        u32::from_be_bytes([self.code, self.decode, self.code1, self.code2])
    }

    /// From the 32-bit NDR value.
    pub const fn from_u32(v: u32) -> PnioStatus {
        let [code, decode, code1, code2] = v.to_be_bytes();
        PnioStatus {
            code,
            decode,
            code1,
            code2,
        }
    }

    /// The four octets as carried inside blocks (IODWriteRes), ErrorCode first.
    pub const fn to_bytes(self) -> [u8; 4] {
        [self.code, self.decode, self.code1, self.code2]
    }
}

/// A record access error: ErrorCode1 of PNIORW (class << 4 | code).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RecordError {
    /// Application: read error (0xA0).
    ReadError,
    /// Application: write error (0xA1).
    WriteError,
    /// Application: feature not supported (0xA9).
    FeatureNotSupported,
    /// Access: invalid index (0xB0).
    InvalidIndex,
    /// Access: write length error (0xB1).
    WriteLength,
    /// Access: invalid slot/subslot (0xB2).
    InvalidSlotSubslot,
    /// Access: type conflict (0xB3).
    TypeConflict,
    /// Access: invalid area/API (0xB4).
    InvalidApi,
    /// Access: state conflict (0xB5).
    StateConflict,
    /// Access: access denied (0xB6).
    AccessDenied,
    /// Access: invalid range (0xB7).
    InvalidRange,
    /// Access: invalid parameter (0xB8).
    InvalidParameter,
    /// Resource: busy (0xC2).
    ResourceBusy,
    /// Resource: unavailable (0xC3).
    ResourceUnavailable,
}

impl RecordError {
    /// Its ErrorCode1.
    pub const fn code1(self) -> u8 {
        match self {
            RecordError::ReadError => 0xA0,
            RecordError::WriteError => 0xA1,
            RecordError::FeatureNotSupported => 0xA9,
            RecordError::InvalidIndex => 0xB0,
            RecordError::WriteLength => 0xB1,
            RecordError::InvalidSlotSubslot => 0xB2,
            RecordError::TypeConflict => 0xB3,
            RecordError::InvalidApi => 0xB4,
            RecordError::StateConflict => 0xB5,
            RecordError::AccessDenied => 0xB6,
            RecordError::InvalidRange => 0xB7,
            RecordError::InvalidParameter => 0xB8,
            RecordError::ResourceBusy => 0xC2,
            RecordError::ResourceUnavailable => 0xC3,
        }
    }

    /// The PNIO status of this error for service `code` (read or write).
    pub const fn status(self, code: u8) -> PnioStatus {
        PnioStatus::rw(code, self.code1())
    }
}
