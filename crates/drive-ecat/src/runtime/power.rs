//! Power-on and power-off of a [`Drive`]: building it for a device
//! variant, loading the saved set, handing the flashes back, the firmware
//! slots.

use super::*;
use crate::Variant;

impl<F: Flash> Drive<F> {
    /// Powers the double-axis drive on: defaults, then the newest saved set
    /// from `flash`. No firmware slots: FoE writes are refused.
    #[inline(always)]
    pub fn new(flash: F) -> Self {
        Self::with_boot(flash, None)
    }

    /// Powers the single-axis drive on ([`Variant::Single`]): as
    /// [`new`](Self::new), without axis B.
    #[inline(always)]
    pub fn new_single_axis(flash: F) -> Self {
        Self::with_boot_for(Variant::Single, flash, None)
    }
}

impl<F: Flash, B: Flash> Drive<F, B> {
    /// The device this drive is.
    pub fn variant(&self) -> Variant {
        self.objects.variant()
    }

    /// Powers the double-axis drive on with the firmware slots `boot` (as
    /// the boot left them: [`BootSlots::boot`] ran and chose the running
    /// slot): FoE firmware downloads in Bootstrap go into the inactive slot.
    #[inline(always)]
    pub fn with_boot(flash: F, boot: Option<BootSlots<B>>) -> Self {
        Self::with_boot_for(Variant::Double, flash, boot)
    }

    /// [`with_boot`](Self::with_boot) for the device `variant`.
    #[inline(always)]
    pub fn with_boot_for(variant: Variant, flash: F, boot: Option<BootSlots<B>>) -> Self {
        let mut drive = Self::unstarted_for(variant, flash, boot);
        drive.start();
        drive
    }

    /// [`unstarted_for`](Self::unstarted_for) the double-axis device.
    #[inline(always)]
    pub fn unstarted(flash: F, boot: Option<BootSlots<B>>) -> Self {
        Self::unstarted_for(Variant::Double, flash, boot)
    }

    /// The drive before [`start`](Self::start): every part at its power-on
    /// value, nothing loaded. A plain value, so a firmware can write it
    /// straight into its static (`MaybeUninit::write`) and start it there:
    /// a drive assembled and loaded in one function needed several copies
    /// of itself on the stack (docs/architecture.md).
    ///
    /// `variant` chooses the device: its description ([`crate::device`]:
    /// identity, SII, PDOs) and its dictionary
    /// ([`DriveObjects::for_variant`]); the single-axis device's axis B
    /// stays idle ([`Drive::control_cycle_with`]).
    #[inline(always)]
    pub fn unstarted_for(variant: Variant, flash: F, boot: Option<BootSlots<B>>) -> Self {
        Self {
            slave: Slave::new(crate::device(variant)),
            eoe: ecat::eoe_queue::EoeQueue::new(),
            objects: DriveObjects::for_variant(variant),
            store: Some(ParamStore::new(flash)),
            boot,
            firmware_stored: None,
            diag: DiagHistory::new(),
            startup: Startup::Defaults,
            last_code: AlStatusCode(0xFFFF),
            pdo: PdoImage::EMPTY,
            pdo_error: None,
            last_state: AlState::Init,
            last_rx_frames: 0,
            axes: [Axis::new(0), Axis::new(1)],
            actions: drive_core::actions::Actions::new(),
            axis_caches: [AxisCache::new(), AxisCache::new()],
            ctl_rx_frames: 0,
            pll: None,
            pll_settings: None,
            sync_shown: None,
            slots: RuntimeSlots::NONE,
            sync_error: None,
            optimizer: dcsync::Optimizer::new(),
            frame_rel_sync0_ns: None,
            step_offsets_ns: (0, 0),
            cycle_pdo: false,
            event52_emcy_sent: [false; 2],
            fault_diag: [None; 2],
            restart_requested: None,
            projected_fieldbus: FIELDBUS_ID,
            wrong_firmware: false,
            sntp_offset_ns: None,
            ports: PortDiag::default(),
            mailbox_er: 0,
            pll_from_sm: false,
        }
    }

    /// Power-on of an [`unstarted`](Self::unstarted) drive: resolves the
    /// cyclic entries, loads the newest saved set, compiles the process
    /// images and fills the live values.
    pub fn start(&mut self) {
        self.slots = RuntimeSlots::resolve(&self.objects);
        self.startup = self.load_saved();
        self.compile_pdo_image();
        self.update_live();
        // E54: the slot a download goes to (the boot decision is made)
        let update_slot = update_slot_value(self.boot.as_ref().map(BootSlots::inactive));
        let _ = self.objects.set(E54, 0, update_slot);
    }

    /// Loads the saved parameter set into the dictionary (defaults stay when
    /// there is none, it is from another layout or does not load).
    fn load_saved(&mut self) -> Startup {
        let mut image = [0u8; PERSISTENT_IMAGE_BYTES];
        let Some(store) = self.store.as_mut() else {
            return Startup::Defaults;
        };
        match store.load(self.objects.layout_hash(), &mut image) {
            Ok(n) => match image.get(..n).map(|img| self.objects.load_persistent(img)) {
                Some(Ok(())) => Startup::Loaded,
                _ => Startup::Defaults,
            },
            Err(
                StoreError::NoData | StoreError::LayoutMismatch | StoreError::TooLarge | StoreError::Flash(_),
            ) => Startup::Defaults,
        }
    }

    /// Whether the saved set was loaded at power-on.
    pub fn startup(&self) -> Startup {
        self.startup
    }

    /// The store's flash (for power-cycle simulation and fault injection);
    /// `None` while a [`SaveJob`] has it.
    pub fn flash_mut(&mut self) -> Option<&mut F> {
        self.store.as_mut().map(ParamStore::flash_mut)
    }

    /// Powers off: gives the flash back (RAM values are lost); `None` when
    /// a [`SaveJob`] has it.
    pub fn into_flash(self) -> Option<F> {
        self.store.map(ParamStore::into_inner)
    }

    /// Powers off: gives the parameter flash (`None` when a [`SaveJob`] has
    /// it) and the firmware slots' flash back.
    pub fn into_flashes(self) -> (Option<F>, Option<B>) {
        (
            self.store.map(ParamStore::into_inner),
            self.boot.map(BootSlots::into_inner),
        )
    }

    /// The firmware slots, if the drive has them.
    pub fn boot_slots(&self) -> Option<&BootSlots<B>> {
        self.boot.as_ref()
    }

    /// The firmware slots, mutable (tests, fault injection).
    pub fn boot_slots_mut(&mut self) -> Option<&mut BootSlots<B>> {
        self.boot.as_mut()
    }

    /// The running firmware confirms itself after a successful start: a
    /// trial image (first start after an update) is kept from now on instead
    /// of being rolled back at the next boot. `false` when the drive has no
    /// slots or the flash failed.
    pub fn confirm_firmware(&mut self) -> bool {
        self.boot.as_mut().is_some_and(|b| b.confirm().is_ok())
    }
}
