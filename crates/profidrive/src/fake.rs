//! A fake drive for the tests: a table of objects with types, rights,
//! limits and values, and a log of the writes.

use std::vec::Vec;

use crate::{Addr, Completion, DataType, Describe, ParamAccess, PdError};

#[derive(Debug, Clone, Copy)]
pub(crate) struct Obj {
    pub addr: Addr,
    pub t: DataType,
    pub read: bool,
    pub write: bool,
    pub value: i64,
    pub max: i64,
}

#[derive(Debug, Clone, Default)]
pub(crate) struct Fake {
    pub objs: Vec<Obj>,
    /// (address, value, cyclic) of every accepted write.
    pub writes: Vec<(Addr, i64, bool)>,
    /// Cycles a write of 971.0 stays pending.
    pub save_cycles: u32,
    pub pending: u32,
    /// Objects of indices not in the table exist without this subindex.
    pub state_lock: bool,
}

const fn o(index: u16, sub: u8, t: DataType, read: bool, write: bool) -> Obj {
    Obj {
        addr: Addr::new(index, sub),
        t,
        read,
        write,
        value: 0,
        max: i64::MAX,
    }
}

impl Fake {
    /// The objects the Example Function block's telegrams map, plus a few.
    pub fn drive() -> Self {
        use DataType::*;
        let objs = std::vec![
            o(967, 0, U16, true, true),
            o(968, 0, U16, true, false),
            o(1050, 0, I8, true, true),
            o(1001, 0, I32, true, true),
            o(1001, 1, I32, true, true),
            o(1001, 2, I32, true, true),
            o(1001, 3, I32, true, true),
            o(1001, 4, I32, true, true),
            o(1001, 5, U32, true, true),
            o(1040, 0, I32, true, true),
            o(0x2415, 2, I32, true, true),
            o(1010, 0, I32, true, true),
            o(1011, 2, U32, true, true),
            o(0x6071, 0, I16, true, true),
            o(0x2416, 2, I32, true, true),
            o(1500, 0, U8, true, true),
            o(1100, 0, I32, true, false),
            o(1101, 0, I32, true, false),
            o(0x6077, 0, I16, true, false),
            o(1141, 0, U32, true, false),
            o(1102, 0, I32, true, false),
            o(971, 0, U16, true, true),
            o(0x6040, 0, U16, false, true),
            o(0x1008, 0, VisibleString(16), true, false),
            o(0x2000, 0, U64, true, true),
            o(1004, 0, U16, true, true),
        ];
        let mut f = Self {
            objs,
            ..Self::default()
        };
        f.obj(Addr::new(1004, 0)).max = 2000;
        f
    }

    pub fn obj(&mut self, a: Addr) -> &mut Obj {
        self.objs
            .iter_mut()
            .find(|x| x.addr == a)
            .expect("object in the fake")
    }

    pub fn value(&self, a: Addr) -> i64 {
        self.objs.iter().find(|x| x.addr == a).map_or(-1, |x| x.value)
    }

    pub fn set(&mut self, a: Addr, v: i64) {
        self.obj(a).value = v;
    }
}

impl ParamAccess for Fake {
    fn describe(&self, addr: Addr) -> Result<Describe, PdError> {
        match self.objs.iter().find(|x| x.addr == addr) {
            Some(x) => Ok(Describe {
                data_type: x.t,
                readable: x.read,
                writable: x.write,
            }),
            None if self.objs.iter().any(|x| x.addr.index == addr.index) => Err(PdError::FAULTY_SUBINDEX),
            None => Err(PdError::IMPERMISSIBLE_PNU),
        }
    }

    fn read(&mut self, addr: Addr) -> Result<i64, PdError> {
        let d = self.describe(addr)?;
        if !d.readable {
            return Err(PdError::IMPERMISSIBLE_PNU);
        }
        Ok(self.value(addr))
    }

    fn write(&mut self, addr: Addr, value: i64, cyclic: bool) -> Result<Completion, PdError> {
        let d = self.describe(addr)?;
        if !d.writable {
            return Err(PdError::CANNOT_CHANGE);
        }
        if self.state_lock && !cyclic {
            return Err(PdError::NOT_IN_STATE);
        }
        let obj = self.obj(addr);
        if value > obj.max {
            return Err(PdError::LIMIT_EXCEEDED);
        }
        obj.value = value;
        self.writes.push((addr, value, cyclic));
        if addr == Addr::new(971, 0) && self.save_cycles > 0 {
            self.pending = self.save_cycles;
            return Ok(Completion::Pending);
        }
        Ok(Completion::Done)
    }

    fn poll_write(&mut self, _addr: Addr) -> Result<Completion, PdError> {
        if self.pending > 1 {
            self.pending -= 1;
            Ok(Completion::Pending)
        } else {
            self.pending = 0;
            Ok(Completion::Done)
        }
    }
}
