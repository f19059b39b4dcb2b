//! The axis' control settings in the one declaration (issue 40): the
//! manufacturer parameters of the motion functions and the cascade that a
//! master sets (groups C, G and I at `parameter_index(group, line)`, axis B
//! at +8000h). The axis reads them when the configuration generation moves
//! (`axis/settings.rs`), never per cycle. The motor data (group B) of the
//! current control will join them here.
//!
//! Merged with [`super::manufacturer::PARAMS`] into one sorted list
//! ([`super::MANUFACTURER_A`]).

use super::{Object, Value};
use crate::parameter_index;
use od::DataType::U16;
use od::{Access, DataType, EntryInfo};

const RW: Access = Access::RW;
const fn e(sub: u8, name: &'static str, t: DataType, a: Access) -> EntryInfo {
    EntryInfo::new(sub, name, t, a)
}
/// Group G parameter `line`.
const fn g(line: u16) -> u16 {
    parameter_index(6, line)
}

/// The control settings of axis A, sorted by index.
pub const PARAMS: [Object; 2] = [
    Object::var(
        g(472),
        Value::Ram,
        entries![e(0, "Positive velocity limit torque mode", U16, RW)
            .range(0, 1000)
            .unit("0.1 %")
            .saved()],
    )
    .axis()
    .level(1)
    .note("G472 (C-039); cst and pt: the speed up to which the torque set-point drives the axis in the positive direction, in 0.1 % of the maximum speed I10; default 0 %: the axis does not move until it is raised; effective at once; not mappable (a configuration value)"),
    Object::var(
        g(475),
        Value::Ram,
        entries![e(0, "Negative velocity limit torque mode", U16, RW)
            .range(0, 1000)
            .unit("0.1 %")
            .saved()],
    )
    .axis()
    .level(1)
    .note("G475 (C-039); as G472 in the negative direction (magnitude)"),
];
