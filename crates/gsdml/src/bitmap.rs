//! The device symbol of the hardware catalogue: a 70 × 40 pixel Windows
//! bitmap (4 bits per pixel, 16-colour palette, 1,558 bytes), the size and
//! format engineering tools show beside a GSDML's devices. Drawn here from a
//! few rectangles (the drive's housing, its front panel, the two RJ45
//! sockets X21 with their link LEDs, the status LEDs), so the file is as
//! reproducible as the GSDML.

const W: usize = 70;
const H: usize = 40;

/// Palette indices.
const WHITE: u8 = 0;
const HOUSING: u8 = 1;
const PANEL: u8 = 2;
const SOCKET: u8 = 3;
const GREEN: u8 = 4;
const RED: u8 = 5;
const EDGE: u8 = 6;

/// BGR0 palette entries (16, unused ones black).
const PALETTE: [[u8; 4]; 7] = [
    [0xFF, 0xFF, 0xFF, 0], // white background
    [0x60, 0x60, 0x60, 0], // housing, dark grey
    [0xC8, 0xC8, 0xC8, 0], // front panel, light grey
    [0x20, 0x20, 0x20, 0], // RJ45 socket
    [0x30, 0xC0, 0x30, 0], // green LED
    [0x30, 0x30, 0xD0, 0], // red LED
    [0x00, 0x00, 0x00, 0], // outline
];

fn fill(px: &mut [[u8; W]; H], x0: usize, y0: usize, w: usize, h: usize, c: u8) {
    for row in px.iter_mut().skip(y0).take(h) {
        for p in row.iter_mut().skip(x0).take(w) {
            *p = c;
        }
    }
}

/// The bitmap file (BITMAPFILEHEADER, BITMAPINFOHEADER, palette, rows
/// bottom-up, each padded to 32 bits).
pub fn device_bitmap() -> Vec<u8> {
    let mut px = [[WHITE; W]; H];
    // housing with an outline, a light front panel on its right
    fill(&mut px, 8, 2, 54, 36, EDGE);
    fill(&mut px, 9, 3, 52, 34, HOUSING);
    fill(&mut px, 40, 5, 19, 30, PANEL);
    // two RJ45 sockets (X21: RTE0, RTE1) with a green link LED each
    for y in [8, 20] {
        fill(&mut px, 44, y, 11, 9, SOCKET);
        fill(&mut px, 45, y + 1, 2, 2, GREEN);
    }
    // status LEDs on the panel: RUN green, SF/BF red
    fill(&mut px, 43, 31, 3, 2, GREEN);
    fill(&mut px, 48, 31, 3, 2, RED);
    fill(&mut px, 53, 31, 3, 2, RED);
    // cooling fins on the housing
    for x in (13..37).step_by(4) {
        fill(&mut px, x, 6, 2, 28, EDGE);
    }

    let row_bytes = (W / 2 + 3) & !3;
    let image = row_bytes * H;
    let offset = 14 + 40 + 16 * 4;
    let size = offset + image;
    let mut b = Vec::with_capacity(size);
    let u32le = |b: &mut Vec<u8>, v: usize| b.extend_from_slice(&(v as u32).to_le_bytes());
    b.extend_from_slice(b"BM");
    u32le(&mut b, size);
    u32le(&mut b, 0);
    u32le(&mut b, offset);
    u32le(&mut b, 40);
    u32le(&mut b, W);
    u32le(&mut b, H);
    b.extend_from_slice(&1u16.to_le_bytes()); // planes
    b.extend_from_slice(&4u16.to_le_bytes()); // bits per pixel
    u32le(&mut b, 0); // BI_RGB
    u32le(&mut b, image);
    u32le(&mut b, 2835); // 72 dpi
    u32le(&mut b, 2835);
    u32le(&mut b, 16);
    u32le(&mut b, 0);
    for i in 0..16 {
        b.extend_from_slice(PALETTE.get(i).unwrap_or(&[0; 4]));
    }
    for row in px.iter().rev() {
        let start = b.len();
        for pair in row.chunks(2) {
            let hi = pair.first().copied().unwrap_or(0);
            let lo = pair.get(1).copied().unwrap_or(0);
            b.push(hi << 4 | lo);
        }
        b.resize(start + row_bytes, 0);
    }
    b
}
