//! Whether a channel is exactly the standard PDO layout (spec §5.4) of one
//! or both axes, so that its copy can be the straight-line one of
//! [`DriveObjects::copy_in_standard`]/[`DriveObjects::copy_out_standard`]
//! instead of its program: the same bytes moved, without a program.

use super::*;
use crate::objects::{Run, AXIS_BLOCK, RX_RUNS, TX_RUNS};
use crate::pdo_maps::{RX_A, RX_B, TX_A, TX_B};
use od::PdoEntry;

/// The number of axes (1: axis A, 2: A then B) whose standard layout
/// `entries` (an image of `bytes` bytes) is exactly: the defaults' entries
/// in order, each at its place in the image and with its RAM slot at its
/// place in the axis' block, of its full width and (RxPDO) no configuration
/// entry; 0 for any other mapping.
pub(super) fn standard_axes(entries: &[ImageEntry], bytes: usize, rx: bool) -> u8 {
    let (a, b, (run0, run1, per_bytes)): (&[PdoEntry], &[PdoEntry], (Run, Run, usize)) = if rx {
        (&RX_A, &RX_B, RX_RUNS)
    } else {
        (&TX_A, &TX_B, TX_RUNS)
    };
    let per = a.len();
    let axes = entries.len() / per;
    if !(1..=2).contains(&axes) || entries.len() != axes * per || bytes != axes * per_bytes {
        return 0;
    }
    let mut img = 0;
    for (k, e) in entries.iter().enumerate() {
        let (axis, j) = (k / per, k % per);
        let Some(want) = (if axis == 0 { a.get(j) } else { b.get(j) }) else {
            return 0;
        };
        if j == 0 {
            img = 0;
        }
        // the runs follow each other in the image: run 0 from 0, run 1 after it
        let run = if img < run0.img + run0.len { run0 } else { run1 };
        let ram = axis * AXIS_BLOCK + run.ram + img.saturating_sub(run.img);
        let width = want.data_type.bytes();
        let placed = e.slot.is_some_and(|s| {
            usize::from(s.ram_offset()) == ram && s.bytes() == width && !(rx && s.is_config())
        });
        if !(placed
            && e.index == want.index
            && e.sub == want.sub
            && e.byte_aligned()
            && e.byte_offset() == axis * per_bytes + img)
        {
            return 0;
        }
        img += width;
    }
    axes as u8
}
