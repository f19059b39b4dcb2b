//! A00 save values (E-018, E-020): the job that takes the persistent
//! values and the store out of the drive, writes the flash without holding
//! it and hands the store back with the result. A09 restart (E-019,
//! E-140): when the firmware or the simulator restarts the device.

use super::*;

/// How long a restart requested by A09 waits, so the master reads the
/// answer to its request first (our choice; the manual gives no time).
pub const RESTART_DELAY: Nanos = Nanos::from_ms(100);

/// Result of the last save, as A00\[2\] shows it.
pub mod save_result {
    /// Saved (or nothing saved yet).
    pub const OK: i64 = 0;
    /// The store refused or failed; the previous set is still intact.
    pub const FAILED: i64 = 1;
}

/// A save in progress ([`Drive::begin_save`]): the persistent values and
/// the parameter store, out of the drive so the slow flash write runs
/// without it (the firmware's idle loop holds no lock meanwhile; the
/// control and ESC tasks keep running). Hand it back with
/// [`Drive::end_save`].
pub struct SaveJob<F: Flash> {
    pub(super) store: ParamStore<F>,
    pub(super) image: [u8; PERSISTENT_IMAGE_BYTES],
    /// The image's length; `None` when the values did not serialise.
    pub(super) len: Option<usize>,
    pub(super) saved: bool,
    /// The layout hash of the drive's variant ([`DriveObjects::layout_hash`]).
    pub(super) hash: u32,
}

impl<F: Flash> SaveJob<F> {
    /// Erases and programs the store (E-018: the previous set stays intact
    /// until the new one is complete).
    pub fn write(&mut self) {
        let image = self.len.and_then(|n| self.image.get(..n));
        self.saved = image.is_some_and(|img| self.store.save(img, self.hash).is_ok());
    }
}

impl<F: Flash, B: Flash> Drive<F, B> {
    /// The dictionary's requests: a save (A00, 1010h) writes the store at
    /// once (`false`: none requested, the store is out in a job, or the
    /// write failed). The firmware's idle loop splits it instead
    /// ([`begin_save`](Self::begin_save)).
    pub(super) fn serve_requests(&mut self) -> bool {
        match self.begin_save() {
            Some(mut job) => {
                job.write();
                self.end_save(job)
            }
            None => false,
        }
    }

    /// A requested save (A00, 1010h) taken out of the drive: the persistent
    /// values and the store, so that the firmware writes the flash
    /// ([`SaveJob::write`]) without holding the drive; `None` without a
    /// request or while another job has the store. A00\[0\] reads 1 (running)
    /// until [`end_save`](Self::end_save).
    pub fn begin_save(&mut self) -> Option<SaveJob<F>> {
        if !self.objects.requests().save {
            return None;
        }
        let store = self.store.take()?;
        // (a restart requested as well stays requested)
        if self.objects.take_requests().restart {
            self.objects.request_restart();
        }
        let mut image = [0u8; PERSISTENT_IMAGE_BYTES];
        let len = self.objects.persistent_image(&mut image).ok();
        Some(SaveJob {
            store,
            image,
            len,
            saved: false,
            hash: self.objects.layout_hash(),
        })
    }

    /// Takes the store back from `job` and shows its result in A00 (E-018).
    /// Returns whether the values were saved.
    pub fn end_save(&mut self, job: SaveJob<F>) -> bool {
        self.store = Some(job.store);
        let _ = self.objects.set(A00, 1, 0);
        let _ = self.objects.set(A00, 2, 100);
        let result = if job.saved {
            save_result::OK
        } else {
            save_result::FAILED
        };
        let _ = self.objects.set(A00, 3, result);
        job.saved
    }

    /// Whether the device is to restart now (A09\[0\] = 1, the A75 action
    /// "restart"; E-019, E-140): [`RESTART_DELAY`] after the request, and
    /// not while a save has the store (the restart waits for its end).
    /// The caller restarts the device as a power cycle does (the firmware
    /// resets the MCU, the simulator powers the drive off and on with its
    /// flashes): the saved values load, a pending firmware image starts.
    pub fn restart_due(&mut self, now: Nanos) -> bool {
        if self.objects.requests().restart && self.restart_requested.is_none() {
            self.restart_requested = Some(now);
        }
        self.restart_requested
            .is_some_and(|t| now.since(t) >= RESTART_DELAY && self.store.is_some())
    }

    /// Writes the persistent values to the store now (A00 / 1010h "save");
    /// `false` when it failed or a [`SaveJob`] has the store.
    pub fn save(&mut self) -> bool {
        self.objects.request_save();
        self.serve_requests()
    }
}
