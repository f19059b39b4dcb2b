//! A small drive for the PROFIdrive targets: the objects of the Example
//! Function block's telegrams, with limits, a read-only and a write-only
//! one, and a save that stays pending for a few cycles.

use profidrive::{Addr, Completion, DataType, Describe, ParamAccess, PdError};

const OBJECTS: [(u16, u8, DataType, bool, bool); 24] = [
    (967, 0, DataType::U16, true, true),
    (968, 0, DataType::U16, true, false),
    (1050, 0, DataType::I8, true, true),
    (1001, 0, DataType::I32, true, true),
    (1001, 1, DataType::I32, true, true),
    (1001, 2, DataType::I32, true, true),
    (1001, 3, DataType::I32, true, true),
    (1001, 4, DataType::I32, true, true),
    (1001, 5, DataType::U32, true, true),
    (1040, 0, DataType::I32, true, true),
    (0x2415, 2, DataType::I32, true, true),
    (1010, 0, DataType::I32, true, true),
    (1011, 2, DataType::U32, true, true),
    (0x6071, 0, DataType::I16, true, true),
    (0x2416, 2, DataType::I32, true, true),
    (1500, 0, DataType::U8, true, true),
    (1100, 0, DataType::I32, true, false),
    (1101, 0, DataType::I32, true, false),
    (0x6077, 0, DataType::I16, true, false),
    (1141, 0, DataType::U32, true, false),
    (971, 0, DataType::U16, true, true),
    (0x6040, 0, DataType::U16, false, true),
    (0x2000, 0, DataType::U64, true, true),
    (0x6060, 0, DataType::Bool, true, true),
];

pub struct Drive {
    pub values: [i64; OBJECTS.len()],
    pending: u8,
}

impl Drive {
    pub fn new() -> Self {
        Self {
            values: [0; OBJECTS.len()],
            pending: 0,
        }
    }

    fn find(addr: Addr) -> Option<usize> {
        OBJECTS.iter().position(|o| o.0 == addr.index && o.1 == addr.sub)
    }
}

impl ParamAccess for Drive {
    fn describe(&self, addr: Addr) -> Result<Describe, PdError> {
        match Self::find(addr) {
            Some(i) => {
                let (_, _, data_type, readable, writable) = OBJECTS[i];
                Ok(Describe {
                    data_type,
                    readable,
                    writable,
                })
            }
            None if OBJECTS.iter().any(|o| o.0 == addr.index) => Err(PdError::FAULTY_SUBINDEX),
            None => Err(PdError::IMPERMISSIBLE_PNU),
        }
    }

    fn read(&mut self, addr: Addr) -> Result<i64, PdError> {
        let i = Self::find(addr).ok_or(PdError::IMPERMISSIBLE_PNU)?;
        Ok(self.values[i])
    }

    fn write(&mut self, addr: Addr, value: i64, _cyclic: bool) -> Result<Completion, PdError> {
        let i = Self::find(addr).ok_or(PdError::IMPERMISSIBLE_PNU)?;
        let (_, _, t, _, writable) = OBJECTS[i];
        assert!(writable, "the profile wrote a read-only object");
        assert!(
            t == DataType::U64 || (value >= t.min_value() && value <= t.max_value()),
            "a value outside {t:?}: {value}"
        );
        if addr.index == 1500 && value > 0x10 {
            return Err(PdError::VALUE_IMPERMISSIBLE);
        }
        self.values[i] = value;
        if addr.index == 971 {
            self.pending = 3;
            return Ok(Completion::Pending);
        }
        Ok(Completion::Done)
    }

    fn poll_write(&mut self, _addr: Addr) -> Result<Completion, PdError> {
        self.pending = self.pending.saturating_sub(1);
        Ok(if self.pending == 0 {
            Completion::Done
        } else {
            Completion::Pending
        })
    }
}
