//! Signed images (issue 18): header v2, signature, load address, security
//! counter, in the download and in the boot decision.
extern crate std;
use std::vec::Vec;

use crate::tests::{body, dev_seed, download, file_for, load, power_cycle, signed, Ram};
use crate::*;

const KEY: [u8; 32] = DEV_PUBLIC_KEY;
/// Another key pair's seed (not the drive's).
const OTHER_SEED: [u8; 32] = [7; 32];

fn boot_v(s: BootSlots<Ram>, min: u32) -> (BootSlots<Ram>, Option<Decision>) {
    let mut s = BootSlots::new(s.into_inner());
    let d = s.boot_verified(&KEY, min).unwrap();
    (s, d)
}

fn download_v(s: &mut BootSlots<Ram>, f: &[u8]) -> Result<Slot, UpdateError> {
    s.begin()?;
    for c in f.chunks(200) {
        s.write(c)?;
    }
    s.finish_verified(&KEY)
}

/// Slot A holds a confirmed signed image with security counter `counter`.
fn factory(counter: u32) -> BootSlots<Ram> {
    let mut s = BootSlots::new(Ram::new());
    assert_eq!(s.boot_verified(&KEY, 0).unwrap(), None);
    let f = signed(Slot::A, &body(1, 3000), 1, counter, &dev_seed());
    assert_eq!(download_v(&mut s, &f), Ok(Slot::A));
    let (mut s, d) = boot_v(s, 0);
    assert_eq!(d.map(|d| (d.slot, d.trial)), Some((Slot::A, true)));
    s.confirm().unwrap();
    assert_eq!(s.security_floor(), counter);
    s
}

/// The byte at `at` of the flash.
fn byte(s: &mut BootSlots<Ram>, at: usize) -> &mut u8 {
    s.flash_mut().bytes_mut().nth(at).unwrap()
}

const SLOT_B: usize = 32 * 256;

#[test]
fn boot_signature_header_v2_layout_and_key_files() {
    let b = body(3, 100);
    let f = signed(Slot::B, &b, 9, 4, &dev_seed());
    assert_eq!(&f[..4], b"SC6F");
    let le = |at: usize| u32::from_le_bytes(f[at..at + 4].try_into().unwrap());
    assert_eq!((le(4), le(8), le(12)), (100, crc32(&b), 9));
    assert_eq!((le(16), le(20), le(24), le(28)), (2, load(Slot::B), 4, 0));
    assert_eq!(f.len(), IMAGE_HEADER_LEN + 100);
    let h = verify_file(&f, &KEY).unwrap();
    assert_eq!(
        (h.version, h.load_address, h.security_counter),
        (9, load(Slot::B), 4)
    );
    assert_eq!(h.to_bytes()[..], f[..IMAGE_HEADER_LEN]);
    // the digest is SHA-256(header[..32] ‖ body)
    use sha2::Digest;
    let mut sha = sha2::Sha256::new();
    sha.update(&f[..SIGNED_HEADER_LEN]);
    sha.update(&b);
    assert_eq!(h.digest(&b)[..], sha.finalize()[..]);
    // the development key pair in keys/ belongs together
    assert_eq!(public_key(&dev_seed()), DEV_PUBLIC_KEY);
    assert_eq!(parse_key_hex(" 00ff\n"), None);
    assert_eq!(parse_key_hex(&"0A".repeat(32)), Some([0x0A; 32]));
    assert_eq!(parse_key_hex(&"0g".repeat(32)), None);
    // the body sits aligned for a vector table
    assert_eq!(BootSlots::<Ram>::body_offset(), 1024);
    assert_eq!(BootSlots::<RamFlash<4096, 8>>::body_offset(), 1024);
    assert_eq!(
        BootSlots::<RamFlash<256, 64>>::new(Ram::new()).capacity(),
        8192 - 1024
    );
    let s = BootSlots::with_base(RamFlash::<4096, 8>::new(), 0x0C00_0000);
    assert_eq!(
        (s.load_address(Slot::A), s.load_address(Slot::B)),
        (0x0C00_0400, 0x0C00_4400)
    );
    // a v1 header (16 bytes, no format word) is not taken
    let mut v1 = f.clone();
    v1[16..20].copy_from_slice(&[0; 4]);
    assert_eq!(ImageHeader::parse(&v1), None);
}

#[test]
fn boot_signature_valid_signed_image_boots() {
    let mut s = factory(1);
    let f = signed(Slot::B, &body(2, 5000), 2, 2, &dev_seed());
    assert_eq!(download_v(&mut s, &f), Ok(Slot::B));
    assert_eq!(s.verify(Slot::B, &KEY).map(|h| h.version), Ok(2));
    let (mut s, d) = boot_v(s, 0);
    assert_eq!(d.map(|d| (d.slot, d.trial)), Some((Slot::B, true)));
    assert_eq!(s.security_floor(), 2, "the running image's counter");
    s.confirm().unwrap();
    let (s, d) = boot_v(s, 0);
    assert_eq!(d.map(|d| (d.slot, d.trial)), Some((Slot::B, false)));
    assert_eq!(s.security_floor(), 2);
    // an equal counter is no downgrade
    let mut s = s;
    let f = signed(Slot::A, &body(3, 500), 3, 2, &dev_seed());
    assert_eq!(download_v(&mut s, &f), Ok(Slot::A));
}

#[test]
fn boot_signature_flipped_body_byte_is_refused() {
    let mut s = factory(1);
    let good = signed(Slot::B, &body(2, 2000), 2, 1, &dev_seed());
    // in the download: the CRC catches it
    let mut bad = good.clone();
    bad[IMAGE_HEADER_LEN + 1234] ^= 0x01;
    assert_eq!(download_v(&mut s, &bad), Err(UpdateError::Crc));
    // the same with a CRC that matches the changed body: the signature
    let mut h = ImageHeader::parse(&bad).unwrap();
    h.crc = crc32(&bad[IMAGE_HEADER_LEN..]);
    bad[..IMAGE_HEADER_LEN].copy_from_slice(&h.to_bytes());
    assert_eq!(download_v(&mut s, &bad), Err(UpdateError::Signature));
    assert_eq!(s.state(Slot::B).unwrap(), SlotState::Empty, "no VALID mark");
    // the unsigned path takes it (CRC only) ...
    assert_eq!(download(&mut s, &bad, 100), Ok(Slot::B));
    // ... the signed boot does not
    assert_eq!(s.verify(Slot::B, &KEY), Err(VerifyError::Signature));
    let (s, d) = boot_v(s, 0);
    assert_eq!(d.map(|d| (d.slot, d.trial)), Some((Slot::A, false)));
    // in flash after a good download: one body byte changes
    let mut s = s;
    assert_eq!(download_v(&mut s, &good), Ok(Slot::B));
    *byte(&mut s, SLOT_B + 1024 + 77) ^= 0x20;
    assert_eq!(s.verify(Slot::B, &KEY), Err(VerifyError::Crc));
    let (_, d) = boot_v(s, 0);
    assert_eq!(d.map(|d| (d.slot, d.trial)), Some((Slot::A, false)));
}

#[test]
fn boot_signature_flipped_header_byte_is_refused() {
    let mut s = factory(1);
    let good = signed(Slot::B, &body(2, 2000), 2, 1, &dev_seed());
    // each signed header field and the signature itself
    for at in [12, 25, 40, 95] {
        let mut bad = good.clone();
        bad[at] ^= 0x01;
        assert_eq!(download_v(&mut s, &bad), Err(UpdateError::Signature), "byte {at}");
        assert_eq!(s.state(Slot::B).unwrap(), SlotState::Empty, "byte {at}");
    }
    // in flash: the version byte of a good image
    assert_eq!(download_v(&mut s, &good), Ok(Slot::B));
    *byte(&mut s, SLOT_B + 12) ^= 0x01;
    assert_eq!(s.verify(Slot::B, &KEY), Err(VerifyError::Signature));
    assert_eq!(
        s.state(Slot::B).unwrap(),
        SlotState::Pending { seq: 2 },
        "CRC-only: pending"
    );
    let (_, d) = boot_v(s, 0);
    assert_eq!(d.map(|d| (d.slot, d.trial)), Some((Slot::A, false)));
}

#[test]
fn boot_signature_wrong_key_is_refused() {
    let mut s = factory(1);
    let other = signed(Slot::B, &body(2, 900), 2, 1, &OTHER_SEED);
    assert_eq!(
        verify_file(&other, &public_key(&OTHER_SEED)).map(|h| h.version),
        Ok(2)
    );
    assert_eq!(download_v(&mut s, &other), Err(UpdateError::Signature));
    // unsigned (zero signature): refused too
    let mut h = ImageHeader::for_body(&body(2, 900), 2, load(Slot::B), 1);
    h.signature = [0; 64];
    let mut zero = h.to_bytes().to_vec();
    zero.extend_from_slice(&body(2, 900));
    assert_eq!(download_v(&mut s, &zero), Err(UpdateError::Signature));
    // an image of the other key in flash does not boot
    assert_eq!(download(&mut s, &other, 300), Ok(Slot::B));
    let (_, d) = boot_v(s, 0);
    assert_eq!(d.map(|d| (d.slot, d.trial)), Some((Slot::A, false)));
    // a key that is no curve point, or not the signer's
    assert!(verify_file(&other, &[0xFF; 32]).is_err());
}

#[test]
fn boot_signature_wrong_load_address_is_refused() {
    let mut s = factory(1);
    // linked for slot A, sent while A runs: it would go to B
    let for_a = signed(Slot::A, &body(2, 900), 2, 1, &dev_seed());
    s.begin().unwrap();
    assert_eq!(
        s.write(&for_a[..150]),
        Err(UpdateError::LoadAddress),
        "at the header"
    );
    assert!(!s.downloading());
    assert_eq!(s.state(Slot::B).unwrap(), SlotState::Empty);
    // an image for A copied into B's flash: signature good, address wrong
    let mut s2 = BootSlots::new(Ram::new());
    s2.boot().unwrap();
    download(&mut s2, &for_a, 64).unwrap();
    let mut a = s2.into_inner();
    let bytes: Vec<u8> = a.bytes_mut().take(SLOT_B).map(|b| *b).collect();
    for (dst, src) in s.flash_mut().bytes_mut().skip(SLOT_B).zip(bytes) {
        *dst = src;
    }
    assert_eq!(s.verify(Slot::B, &KEY), Err(VerifyError::LoadAddress));
    let (_, d) = boot_v(s, 0);
    assert_eq!(d.map(|d| d.slot), Some(Slot::A));
}

#[test]
fn boot_signature_lower_security_counter_is_refused() {
    let mut s = factory(5);
    // the download: refused at the header, before the body is written
    let old = signed(Slot::B, &body(2, 900), 2, 4, &dev_seed());
    s.begin().unwrap();
    assert_eq!(s.write(&old[..100]), Err(UpdateError::Downgrade));
    assert_eq!(download_v(&mut s, &old), Err(UpdateError::Downgrade));
    assert_eq!(s.state(Slot::B).unwrap(), SlotState::Empty);
    // the boot: an old, validly signed image written into B behind the
    // download's back (say, with a probe) is not started
    let mut s2 = BootSlots::new(Ram::new());
    s2.boot().unwrap();
    download(&mut s2, &file_for(Slot::A, &[0; 8], 0), 8).unwrap();
    let mut s2 = BootSlots::new(s2.into_inner());
    s2.boot().unwrap();
    s2.confirm().unwrap();
    assert_eq!(
        download(&mut s2, &old, 100),
        Ok(Slot::B),
        "no floor on that drive"
    );
    let mut other = s2.into_inner();
    let bytes: Vec<u8> = other.bytes_mut().skip(SLOT_B).map(|b| *b).collect();
    for (dst, src) in s.flash_mut().bytes_mut().skip(SLOT_B).zip(bytes) {
        *dst = src;
    }
    assert_eq!(s.state(Slot::B).unwrap(), SlotState::Pending { seq: 2 });
    assert_eq!(s.verify(Slot::B, &KEY).map(|h| h.security_counter), Ok(4));
    let (s, d) = boot_v(s, 0);
    assert_eq!(
        d.map(|d| (d.slot, d.trial)),
        Some((Slot::A, false)),
        "counter 4 < 5"
    );
    // the CRC-only boot would have started it
    let (_, d) = power_cycle(s);
    assert_eq!(d.map(|d| (d.slot, d.trial)), Some((Slot::B, true)));
}

#[test]
fn boot_signature_floor_from_confirmed_images_and_the_board_minimum() {
    // a trial image never confirmed does not raise the floor: rollback works
    let mut s = factory(1);
    let f = signed(Slot::B, &body(2, 700), 2, 3, &dev_seed());
    assert_eq!(download_v(&mut s, &f), Ok(Slot::B));
    let (s, d) = boot_v(s, 0);
    assert_eq!(d.map(|d| (d.slot, d.trial)), Some((Slot::B, true)));
    let (s, d) = boot_v(s, 0);
    assert_eq!(
        d,
        Some(Decision {
            slot: Slot::A,
            trial: false,
            rolled_back: Some(Slot::B)
        })
    );
    assert_eq!(s.security_floor(), 1);
    // the board's minimum (e.g. an OTP word) above the confirmed image: only
    // the trial image reaches it, and above both nothing starts
    let (s, d) = boot_v(s, 2);
    assert_eq!(d.map(|d| (d.slot, d.trial)), Some((Slot::B, false)));
    let (_, d) = boot_v(s, 4);
    assert_eq!(d, None);
}

fn hex<const N: usize>(s: &str) -> [u8; N] {
    let v: Vec<u8> = (0..s.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&s[i..i + 2], 16).unwrap())
        .collect();
    v.try_into().unwrap()
}

/// RFC 8032 §7.1, tests 1 and 2: our verifier (sha2's SHA-512, our ladder over
/// salty's points) accepts the published signatures and refuses them changed.
#[test]
fn ed25519_verify_takes_the_rfc_8032_test_vectors() {
    let vectors: [(&str, &[u8], &str); 2] = [
        (
            "d75a980182b10ab7d54bfed3c964073a0ee172f3daa62325af021a68f707511a",
            b"",
            "e5564300c360ac729086e2cc806e828a84877f1eb8e5d974d873e065224901555fb8821590a33bacc61e39701cf9b46bd25bf5f0595bbe24655141438e7a100b",
        ),
        (
            "3d4017c3e843895a92b70aa74d1b7ebc9c982ccf2ec4968cc0cd55f12af4660c",
            &[0x72],
            "92a009a9f0d4cab8720e820b5f642540a2b27b5416503f8fb3762223ebdb69da085ac1e43e15996e458f3613d0f11d8c387b2eaeb4302aeeb00d291612bb0c00",
        ),
    ];
    for (key, msg, sig) in vectors {
        let (key, sig) = (hex::<32>(key), hex::<64>(sig));
        assert_eq!(ed25519_verify(&key, msg, &sig), Ok(()));
        let mut bad = sig;
        bad[10] ^= 1;
        assert_eq!(ed25519_verify(&key, msg, &bad), Err(VerifyError::Signature));
        assert_eq!(ed25519_verify(&key, b"other", &sig), Err(VerifyError::Signature));
    }
}

/// Our verifier agrees with salty's own `PublicKey::verify` on signatures of
/// many keys and messages, and on every one of them with one bit changed.
#[test]
fn ed25519_verify_agrees_with_salty() {
    for n in 0u8..24 {
        let seed = [n.wrapping_mul(37).wrapping_add(1); 32];
        let pair = salty::Keypair::from(&seed);
        let key = *pair.public.as_bytes();
        let msg: Vec<u8> = (0..usize::from(n) * 7).map(|i| i as u8 ^ n).collect();
        let sig = pair.sign(&msg).to_bytes();
        assert_eq!(ed25519_verify(&key, &msg, &sig), Ok(()));
        let salty_ok = |s: &[u8; 64]| pair.public.verify(&msg, &salty::Signature::from(s)).is_ok();
        let mut bad = sig;
        bad[usize::from(n) * 2 % 64] ^= 1 << (n % 8);
        assert_eq!(ed25519_verify(&key, &msg, &bad).is_ok(), salty_ok(&bad));
        assert!(ed25519_verify(&key, &msg, &bad).is_err());
    }
}

/// The boot loader's table (`BootApi`) carries a verification result as a
/// code: every refusal stays a refusal on the image's side, a key error stays
/// a key error.
#[test]
fn boot_api_codes_carry_the_verification_result() {
    for r in [
        Ok(()),
        Err(VerifyError::Signature),
        Err(VerifyError::Key),
        Err(VerifyError::Header),
    ] {
        let back = boot_api_result(boot_api_code(r));
        assert_eq!(back.is_ok(), r.is_ok());
        assert_eq!(back == Err(VerifyError::Key), r == Err(VerifyError::Key));
    }
    assert_eq!(boot_api_result(7), Err(VerifyError::Signature));
    assert_eq!(BOOT_API_MAGIC, *b"SC6BAPI1");
}
