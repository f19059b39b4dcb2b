//! Context management (to be written).
