//! The object tables' shorthand: an entry in one call, a parameter's index
//! by its group letter and line.

use crate::parameter_index;
use od::{Access, DataType, EntryInfo};

/// Entry `sub` named `name` of type `t` with access `a`.
pub(super) const fn e(sub: u8, name: &'static str, t: DataType, a: Access) -> EntryInfo {
    EntryInfo::new(sub, name, t, a)
}

/// Group A parameter `line`.
pub(super) const fn a(line: u16) -> u16 {
    parameter_index(0, line)
}

/// Group C parameter `line`.
pub(super) const fn c(line: u16) -> u16 {
    parameter_index(2, line)
}

/// Group E parameter `line`.
pub(super) const fn e_(line: u16) -> u16 {
    parameter_index(4, line)
}

/// Group F parameter `line`.
pub(super) const fn f(line: u16) -> u16 {
    parameter_index(5, line)
}

/// Group G parameter `line`.
pub(super) const fn g(line: u16) -> u16 {
    parameter_index(6, line)
}

/// Group I parameter `line`.
pub(super) const fn i_(line: u16) -> u16 {
    parameter_index(8, line)
}

/// Group J parameter `line`.
pub(super) const fn j(line: u16) -> u16 {
    parameter_index(9, line)
}
