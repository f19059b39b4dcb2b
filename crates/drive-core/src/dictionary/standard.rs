//! The standard PDO layout's copy (spec §5.4: the defaults of 1600h/1601h
//! and 1A00h/1A01h) as straight-line loads and stores: the layout's values
//! lie in two runs per axis at compile-time places of the axis' block
//! ([`crate::objects::AXIS_BLOCK`]), so the copy needs neither a program
//! nor a bounds check per value. [`crate::pdo_image`] takes it when a
//! channel's mapping is exactly the standard one of one or both axes, and
//! copies the same bytes its program would.

use super::*;
use crate::objects::{Run, AXIS_BLOCK, RX_RUNS, TX_RUNS};

/// Bytes of one axis' standard RxPDO (23) and TxPDO (29).
pub(crate) const RX_BYTES: usize = RX_RUNS.2;
/// Bytes of one axis' standard TxPDO.
pub(crate) const TX_BYTES: usize = TX_RUNS.2;

// the pieces below are written for these runs: 6040h…6071h (19 bytes) and
// 60FEh:01 (4); 6041h…60FDh (21) and 60E4h:01…A67 (8)
const _: () = assert!(RX_RUNS.0.len == 19 && RX_RUNS.1.len == 4 && RX_BYTES == 23);
const _: () = assert!(TX_RUNS.0.len == 21 && TX_RUNS.1.len == 8 && TX_BYTES == 29);

/// Copies `N` bytes of `src` at `from` to `dst` at `to` (both ranges
/// constant after inlining into a copy of fixed-size arrays: the checks fold
/// away).
#[inline(always)]
fn piece<const N: usize>(dst: &mut [u8], to: usize, src: &[u8], from: usize) {
    if let (Some(d), Some(s)) = (dst.get_mut(to..to + N), src.get(from..from + N)) {
        d.copy_from_slice(s);
    }
}

/// One axis' standard RxPDO `src` into its block.
#[inline(always)]
fn rx_axis(block: &mut [u8; AXIS_BLOCK], src: &[u8; RX_BYTES]) {
    let (Run { ram: r, img: i, .. }, Run { ram: r1, img: i1, .. }) = (RX_RUNS.0, RX_RUNS.1);
    piece::<8>(block, r, src, i);
    piece::<8>(block, r + 8, src, i + 8);
    piece::<2>(block, r + 16, src, i + 16);
    piece::<1>(block, r + 18, src, i + 18);
    piece::<4>(block, r1, src, i1);
}

/// One axis' standard TxPDO from its block into `dst`.
#[inline(always)]
fn tx_axis(block: &[u8; AXIS_BLOCK], dst: &mut [u8; TX_BYTES]) {
    let (Run { ram: r, img: i, .. }, Run { ram: r1, img: i1, .. }) = (TX_RUNS.0, TX_RUNS.1);
    piece::<8>(dst, i, block, r);
    piece::<8>(dst, i + 8, block, r + 8);
    piece::<4>(dst, i + 16, block, r + 16);
    piece::<1>(dst, i + 20, block, r + 20);
    piece::<8>(dst, i1, block, r1);
}

impl DriveObjects {
    /// The standard RxPDO of axis A (`axes` = 1) or of both axes (2, axis
    /// B's after A's) from `src` into the axis blocks; `src` shorter than the
    /// image copies nothing (the caller takes the per-entry copy then).
    #[inline(always)]
    pub(crate) fn copy_in_standard(&mut self, src: &[u8], axes: u8) {
        let Some((a, rest)) = self.image.split_first_chunk_mut::<AXIS_BLOCK>() else {
            return;
        };
        let Some((sa, src_b)) = src.split_first_chunk::<RX_BYTES>() else {
            return;
        };
        rx_axis(a, sa);
        if axes > 1 {
            if let (Some(b), Some(sb)) = (
                rest.first_chunk_mut::<AXIS_BLOCK>(),
                src_b.first_chunk::<RX_BYTES>(),
            ) {
                rx_axis(b, sb);
            }
        }
    }

    /// The standard TxPDO of axis A (`axes` = 1) or of both axes (2) from
    /// the axis blocks into `dst`.
    #[inline(always)]
    pub(crate) fn copy_out_standard(&self, dst: &mut [u8], axes: u8) {
        let Some((a, rest)) = self.image.split_first_chunk::<AXIS_BLOCK>() else {
            return;
        };
        let Some((da, dst_b)) = dst.split_first_chunk_mut::<TX_BYTES>() else {
            return;
        };
        tx_axis(a, da);
        if axes > 1 {
            if let (Some(b), Some(db)) = (
                rest.first_chunk::<AXIS_BLOCK>(),
                dst_b.first_chunk_mut::<TX_BYTES>(),
            ) {
                tx_axis(b, db);
            }
        }
    }
}
