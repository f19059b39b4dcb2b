//! A small controller for tests: the Example Function block ([`ExampleFb`])
//! on the in-process controller ([`PnController`]) against one simulated
//! drive, one telegram per 1 ms cycle; the FB's inputs are set directly and
//! its outputs read after each cycle.

use super::controller::PnController;
use super::{ExampleFb, FbInputs, FbOutputs};
use crate::pcap::Recording;
use crate::pn::PnSim;
use nanos::Nanos;

/// The FB, its inputs and outputs, and the controller.
pub struct FbRig {
    /// The controller (the drive behind it: [`PnController::sim`]).
    pub ctl: PnController,
    fb: ExampleFb,
    /// The FB's inputs, sent with the next cycle.
    pub i: FbInputs,
    /// The FB's outputs from the last response telegram.
    pub o: FbOutputs,
}

impl FbRig {
    /// `sim` connected at 10 ms (its start-up done), the FB at rest.
    pub fn connect(sim: PnSim) -> Result<FbRig, String> {
        FbRig::recorded(sim, None)
    }

    /// [`connect`](Self::connect), every frame from the Connect on in
    /// `pcap`.
    pub fn recorded(sim: PnSim, pcap: Option<Recording>) -> Result<FbRig, String> {
        let ctl = PnController::connect(sim, Nanos::from_ms(10), pcap)?;
        Ok(FbRig {
            ctl,
            fb: ExampleFb::new(),
            i: FbInputs::default(),
            o: *ExampleFb::new().outputs(),
        })
    }

    /// One cycle: the telegram from the inputs out, the response's outputs
    /// taken when one came.
    pub fn cycle(&mut self) -> Result<(), String> {
        let t = self.fb.receive_telegram(&self.i);
        let r = self.ctl.exchange(&t)?.map(<[u8]>::to_vec);
        if let (Some(r), true) = (r, self.ctl.fresh()) {
            if let Ok(o) = self.fb.response(&r, self.i.drive_enable) {
                self.o = *o;
            }
        }
        Ok(())
    }

    /// Cycles until `done` holds on fresh outputs, at most `ms`; whether it
    /// did.
    pub fn until(&mut self, ms: u64, done: impl Fn(&FbOutputs) -> bool) -> Result<bool, String> {
        for _ in 0..ms {
            self.cycle()?;
            if self.ctl.fresh() && done(&self.o) {
                return Ok(true);
            }
        }
        Ok(false)
    }

    /// Axis A's motor position, increments (the plant).
    pub fn encoder(&self) -> i64 {
        self.ctl.sim().motor(0).map_or(0, |m| m.position_inc_i64())
    }

    /// `drive_enable` until `drive_is_enabled` (the FB's enable sequence).
    pub fn enable(&mut self) -> Result<bool, String> {
        if !self.until(100, |o| o.identifier != 0)? {
            return Ok(false);
        }
        self.enable_within(500)
    }

    /// `drive_enable` set, then cycles until `drive_is_enabled`, at most
    /// `ms`; whether it came.
    pub fn enable_within(&mut self, ms: u64) -> Result<bool, String> {
        self.i.drive_enable = true;
        self.until(ms, |o| o.drive_is_enabled)
    }
}
