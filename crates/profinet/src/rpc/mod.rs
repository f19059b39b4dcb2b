//! DCE/RPC (to be written).
