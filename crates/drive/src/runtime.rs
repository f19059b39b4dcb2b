//! The drive's communication runtime: the slave stack, the object dictionary
//! and the non-volatile store composed once, so the firmware and the
//! simulator run the same code.
//!
//! Each [`Drive::poll`] runs the slave stack over the given PDI, then feeds
//! the live objects that mirror the EtherCAT state (A254, A255, A256, A257[3])
//! and serves the dictionary's requests: "save values" (A00, 1010h) writes the
//! persistent image through [`store::ParamStore`]; at construction the newest
//! saved image is loaded (E-018, E-020).

use crate::dictionary::{DriveObjects, LiveValues, PERSISTENT_IMAGE_BYTES};
use crate::objects::LAYOUT_HASH;
use crate::DEVICE;
use ecat::diag::{DiagHistory, DiagMessage, DiagType};
use ecat::{Slave, StateChange};
use esc::{regs, AlStatusCode, Pdi, PdiExt};
use od::SdoAbort;
use store::{Flash, ParamStore, StoreError};

/// A00 "Save values": [0] start (sub 1), [1] progress (sub 2), [2] result (sub 3),
/// in the SDO-Info numbering the runtime always uses.
const A00: u16 = crate::parameter_index(0, 0);
/// A254 station alias, A255 device state, A256 station address, A257 diagnosis texts.
const A254: u16 = crate::parameter_index(0, 254);
const A255: u16 = crate::parameter_index(0, 255);
const A256: u16 = crate::parameter_index(0, 256);
const A257: u16 = crate::parameter_index(0, 257);

/// Result of the last save, as A00[2] shows it.
pub mod save_result {
    /// Saved (or nothing saved yet).
    pub const OK: i64 = 0;
    /// The store refused or failed; the previous set is still intact.
    pub const FAILED: i64 = 1;
}

/// Diag code of a refused ESM transition: this prefix | AL status code (our
/// choice; the message texts belong in the ESI).
pub const DIAG_AL_STATUS: u32 = 0xE000_0000;

/// The live objects the runtime owns: 10F3h from the diagnosis history.
struct Live<'a> {
    diag: &'a mut DiagHistory,
}

impl LiveValues for Live<'_> {
    fn read(&mut self, index: u16, sub: u8, buf: &mut [u8]) -> Option<Result<usize, SdoAbort>> {
        (index == 0x10F3).then(|| self.diag.read(sub, buf))
    }

    fn write(&mut self, index: u16, sub: u8, data: &[u8]) -> Result<(), SdoAbort> {
        if index == 0x10F3 {
            self.diag.write(sub, data)
        } else {
            Ok(())
        }
    }
}

/// What happened to the saved parameters at start-up.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Startup {
    /// A saved set was loaded.
    Loaded,
    /// Nothing saved yet (or from another firmware layout): defaults.
    Defaults,
}

/// One drive on the bus: slave stack + object dictionary + parameter store.
pub struct Drive<F: Flash> {
    /// The EtherCAT slave stack.
    pub slave: Slave,
    /// The object dictionary (values in RAM).
    pub objects: DriveObjects,
    store: ParamStore<F>,
    /// Diagnosis history 10F3h (volatile, E-145).
    pub diag: DiagHistory,
    startup: Startup,
    last_code: AlStatusCode,
}

impl<F: Flash> Drive<F> {
    /// Powers the drive on: defaults, then the newest saved set from `flash`.
    pub fn new(flash: F) -> Self {
        let mut store = ParamStore::new(flash);
        let mut objects = DriveObjects::new();
        let mut image = [0u8; PERSISTENT_IMAGE_BYTES];
        let startup = match store.load(LAYOUT_HASH, &mut image) {
            Ok(n) => match image.get(..n).map(|img| objects.load_persistent(img)) {
                Some(Ok(())) => Startup::Loaded,
                _ => Startup::Defaults,
            },
            Err(
                StoreError::NoData | StoreError::LayoutMismatch | StoreError::TooLarge | StoreError::Flash(_),
            ) => Startup::Defaults,
        };
        let mut drive = Self {
            slave: Slave::new(&DEVICE),
            objects,
            store,
            diag: DiagHistory::new(),
            startup,
            last_code: AlStatusCode(0xFFFF),
        };
        drive.update_live();
        drive
    }

    /// Whether the saved set was loaded at power-on.
    pub fn startup(&self) -> Startup {
        self.startup
    }

    /// The store's flash (for power-cycle simulation and fault injection).
    pub fn flash_mut(&mut self) -> &mut F {
        self.store.flash_mut()
    }

    /// Powers off: gives the flash back (RAM values are lost).
    pub fn into_flash(self) -> F {
        self.store.into_inner()
    }

    /// Runs the slave stack once at `now_ns`, then the live objects and the
    /// dictionary's requests.
    pub fn poll<P: Pdi>(&mut self, pdi: &mut P, now_ns: u64) -> Result<Option<StateChange>, P::Error> {
        let mut live = Live { diag: &mut self.diag };
        let change = self
            .slave
            .poll(pdi, &mut self.objects.with_live(&mut live), now_ns)?;
        if let Some(c) = change.filter(|c| c.code != AlStatusCode::NO_ERROR) {
            // a refused state change is an error message in the history (E-144)
            let msg = DiagMessage::new(DIAG_AL_STATUS | u32::from(c.code.0), DiagType::Error, c.code.0);
            self.diag.push(msg, now_ns);
        }
        if change.is_some() {
            // A254/A256 as the ESC has them after the master's configuration
            let alias = pdi.read_u16(regs::STATION_ALIAS)?;
            let address = pdi.read_u16(regs::STATION_ADDRESS)?;
            let _ = self.objects.set(A254, 0, i64::from(alias));
            let _ = self.objects.set(A256, 0, i64::from(address));
        }
        self.update_live();
        let requests = self.objects.take_requests();
        if requests.save {
            self.save();
        }
        Ok(change)
    }

    /// Reads an object as the bus sees it (live values included), without the bus.
    pub fn read_object(
        &mut self,
        index: u16,
        sub: u8,
        buf: &mut [u8],
        state: od::CommState,
    ) -> Result<usize, SdoAbort> {
        use od::Dictionary as _;
        let mut live = Live { diag: &mut self.diag };
        self.objects.with_live(&mut live).read(index, sub, buf, state)
    }

    /// Writes the persistent values to the store (A00 / 1010h "save").
    pub fn save(&mut self) -> bool {
        let mut image = [0u8; PERSISTENT_IMAGE_BYTES];
        let saved = match self.objects.persistent_image(&mut image) {
            Ok(n) => image
                .get(..n)
                .is_some_and(|img| self.store.save(img, LAYOUT_HASH).is_ok()),
            Err(_) => false,
        };
        let _ = self.objects.set(A00, 1, 0);
        let _ = self.objects.set(A00, 2, 100);
        let _ = self.objects.set(
            A00,
            3,
            if saved {
                save_result::OK
            } else {
                save_result::FAILED
            },
        );
        saved
    }

    /// A255 (state, +16 with error) and A257[3] ("AL xxxx") follow the slave.
    fn update_live(&mut self) {
        let state = i64::from(self.slave.state().code()) + if self.slave.error() { 16 } else { 0 };
        let _ = self.objects.set(A255, 0, state);
        let code = self.slave.al_status_code();
        if code != self.last_code {
            self.last_code = code;
            let mut text = *b"AL 0000";
            for (i, slot) in text.iter_mut().skip(3).enumerate() {
                let nibble = (code.0 >> (12 - 4 * i)) & 0xF;
                *slot = b"0123456789ABCDEF"
                    .get(usize::from(nibble))
                    .copied()
                    .unwrap_or(b'?');
            }
            let _ = self.objects.set_bytes(A257, 4, &text);
        }
    }
}
