//! The drivers against the register model (crate::model), which behaves as
//! the reference manual describes the hardware.
#![allow(clippy::indexing_slicing, clippy::unwrap_used)]

use crate::adc::{Adc, Samples};
use crate::enc::{Encoder, EncoderPins};
use crate::model::Model;
use crate::pins::{self, AXIS_A};
use crate::pwm::{compare, Pwm, PwmConfig, DUTY_HALF};
use crate::regs::*;
use crate::timer::{self, CycleTimer};
use crate::{Regs, F_CCU_HZ};

fn pwm16k() -> PwmConfig {
    PwmConfig::new(F_CCU_HZ, 16_000, 500).unwrap()
}

#[test]
fn pwm_period_and_dead_time_give_the_rate_asked_for() {
    let c = pwm16k();
    // centre aligned: one period is 2 · (PR + 1) clocks
    assert_eq!(F_CCU_HZ / (2 * (u32::from(c.period) + 1)), 16_000);
    assert_eq!(u32::from(c.period), 4499);
    // 500 ns at 144 MHz = 72 clocks
    assert_eq!(c.dead_time, 72);
    let c8 = PwmConfig::new(F_CCU_HZ, 8_000, 500).unwrap();
    assert_eq!(F_CCU_HZ / (2 * (u32::from(c8.period) + 1)), 8_000);
    assert_eq!(PwmConfig::new(F_CCU_HZ, 0, 500), None);
    assert_eq!(
        PwmConfig::new(F_CCU_HZ, 16_000, 2_000),
        None,
        "dead time over 255 clocks"
    );
    assert_eq!(PwmConfig::new(F_CCU_HZ, 1_000, 100), None, "period over 16 bits");
}

#[test]
fn pwm_waits_for_the_global_start_then_runs_centre_aligned_at_half_duty() {
    let mut m = Model::new();
    let c = pwm16k();
    let a = Pwm::init(&mut m, CCU80, c, true);
    let b = Pwm::init(&mut m, CCU81, c, false);
    for module in [CCU80, CCU81] {
        for y in 0..3 {
            let s = slice(module, y);
            assert_eq!(m.get(s + TCST) & TRB, 0, "stopped until the global start");
            assert_eq!(
                m.get(s + PR),
                u32::from(c.period),
                "period transferred while stopped"
            );
            assert_eq!(m.get(s + CR1), (u32::from(c.period) + 1) >> 1);
            assert_ne!(m.get(s + TC) & TC_TCM, 0, "centre aligned");
            assert_eq!(m.get(s + DC1R), 72 * 0x101);
            assert!(!m.passive(module, y));
        }
        m.global_start(module);
        assert!((0..3).all(|y| m.get(slice(module, y) + TCST) & TRB != 0));
    }
    assert_eq!(a.period(), b.period());
}

#[test]
fn duties_reach_the_compare_registers_only_at_the_next_period_boundary() {
    let mut m = Model::new();
    let c = pwm16k();
    let pwm = Pwm::init(&mut m, CCU80, c, true);
    m.global_start(CCU80);
    let duty = [0, DUTY_HALF, 0xFFFF];
    pwm.set_duties(&mut m, duty);
    let half = (u32::from(c.period) + 1) >> 1;
    assert!(
        (0..3).all(|y| m.get(slice(CCU80, y) + CR1) == half),
        "no transfer mid-period"
    );
    m.boundary(CCU80, false);
    let n = f64::from(c.period) + 1.0;
    for (y, d) in duty.into_iter().enumerate() {
        let cr = m.get(slice(CCU80, y as u32) + CR1);
        assert_eq!(cr, compare(c.period, d));
        // ST1 (high side) active while the counter is ≥ CR1: on-time fraction
        let on = (n - f64::from(cr)).max(0.0) / n;
        assert!((on - f64::from(d) / 65536.0).abs() <= 1.0 / n, "phase {y}: {on}");
    }
    assert_eq!(compare(c.period, 0), u32::from(c.period) + 1, "0 %: never set");
}

#[test]
fn the_trap_input_forces_the_outputs_passive_until_cleared_with_the_input_gone() {
    let mut m = Model::new();
    let pwm = Pwm::init(&mut m, CCU80, pwm16k(), true);
    m.global_start(CCU80);
    m.trap_pin(CCU80, true); // over-current comparator pulls low
    assert!(pwm.trapped(&mut m));
    assert!((0..3).all(|y| m.passive(CCU80, y)));
    m.trap_pin(CCU80, false);
    m.boundary(CCU80, false);
    assert!(
        (0..3).all(|y| m.passive(CCU80, y)),
        "latched: the input going away is not enough"
    );
    m.trap_pin(CCU80, true);
    pwm.clear_trap(&mut m);
    m.boundary(CCU80, false);
    assert!(pwm.trapped(&mut m), "cannot be cleared while the input is active");
    m.trap_pin(CCU80, false);
    pwm.clear_trap(&mut m);
    assert!(!pwm.trapped(&mut m));
    assert!(
        (0..3).all(|y| m.passive(CCU80, y)),
        "leaves only at the period boundary"
    );
    m.boundary(CCU80, false);
    assert!((0..3).all(|y| !m.passive(CCU80, y)));
}

#[test]
fn the_adc_converts_all_five_signals_on_the_pwm_centre_and_each_result_reads_once() {
    let mut m = Model::new();
    let _pwm = Pwm::init(&mut m, CCU80, pwm16k(), true);
    let adc = Adc::init(&mut m);
    assert_eq!(
        m.get(VADC + GLOBCFG) & 0x1F,
        crate::adc::DIVA,
        "divider kept by the SUCAL write"
    );
    for (i, &(g, ch, _)) in crate::adc::MAP.iter().enumerate() {
        m.analog.insert((g, ch), 1000 + 100 * i as u16);
    }
    assert_eq!(adc.read(&mut m), None, "nothing converted before a trigger");
    m.global_start(CCU80);
    m.boundary(CCU80, false); // period match: no trigger
    assert_eq!(adc.read(&mut m), None);
    m.boundary(CCU80, true); // one match: CCU80.SR2 → trigger I
                             // the trigger, then the DC link's result (group 0's last) → VADC0_G0_0
    assert_eq!(m.sr, [(CCU80, 2), (vadc_group(0), 0)]);
    assert_eq!(
        adc.read(&mut m),
        Some(Samples {
            iu: [1000, 1100],
            iv: [1200, 1300],
            udc: 1400
        })
    );
    assert_eq!(adc.read(&mut m), None, "valid flags cleared by the read");
}

#[test]
fn the_encoder_counts_both_ways_across_the_16_bit_wrap_and_reports_the_index_once() {
    let mut m = Model::new();
    let mut a = Encoder::init(&mut m, POSIF0, CCU40, EncoderPins([0, 0, 0]));
    let mut b = Encoder::init(&mut m, POSIF1, CCU41, EncoderPins([1, 1, 1]));
    assert_eq!(m.get(POSIF1 + PCONF) >> 8 & 0x3F, 0b01_01_01);
    m.quad(POSIF0, 1000);
    assert_eq!(a.position(&mut m), 1000);
    for _ in 0..4 {
        m.quad(POSIF0, -30_000);
        a.position(&mut m);
    }
    assert_eq!(a.position(&mut m), 1000 - 120_000);
    m.quad(POSIF1, 70_000);
    // more than half the counter between two reads cannot be told apart
    assert_eq!(b.position(&mut m), 70_000 - 65_536);
    assert!(!a.take_index(&mut m));
    m.index(POSIF0);
    assert!(a.take_index(&mut m));
    assert!(!a.take_index(&mut m));
    assert!(!b.take_index(&mut m));
}

#[test]
fn the_control_timer_fires_ccu40_sr0_once_after_the_armed_delay() {
    let mut m = Model::new();
    let t = CycleTimer::init(&mut m);
    assert_eq!(m.get(slice(CCU40, 3) + PSC), timer::PRESCALER);
    t.arm(&mut m, 250_000);
    let ticks = 250_000 * u64::from(timer::TICK_HZ) / 1_000_000_000;
    m.advance(CCU40, 3, ticks as u32 - 1);
    assert!(m.sr.is_empty());
    m.advance(CCU40, 3, 1);
    assert_eq!(m.sr, [(CCU40, 0)]);
    m.advance(CCU40, 3, 100_000);
    assert_eq!(m.sr.len(), 1, "single shot");
    t.arm(&mut m, 1_000);
    m.advance(CCU40, 3, 9);
    assert_eq!(m.sr.len(), 2);
    assert_eq!(CycleTimer::ticks(1_000_000_000), 0xFFFF, "capped to one shot");
    assert_eq!(CycleTimer::ticks(0), 1);
}

#[test]
fn sync0_reaches_eru1_sr0() {
    let mut m = Model::new();
    timer::route_sync0(&mut m);
    m.eru1_edge(timer::SYNC0_EXS0B ^ 0b11);
    assert!(m.sr.is_empty());
    m.eru1_edge(timer::SYNC0_EXS0B);
    assert_eq!(m.sr, [(ERU1, 0)]);
}

#[test]
fn a_disabled_axis_holds_its_pwm_pins_low_and_an_enabled_one_gives_them_to_ccu8() {
    let mut m = Model::new();
    m.write(port(0) + IOCR0 + 4, 0xFFFF_FFFF); // pins 4…7 set to something else
    m.write(port(0) + OMR, 0x3F); // latches high
    pins::set_axis(&mut m, &AXIS_A, false);
    assert_eq!(m.get(port(0)) & 0x3F, 0, "outputs low");
    let field = |m: &Model, p: u32| (m.get(port(0) + IOCR0 + 4 * (p / 4)) >> (8 * (p % 4) + 3)) & 0x1F;
    assert!((0..6).all(|p| field(&m, p) == PC_GPIO_OUT));
    assert_eq!(field(&m, 6), 0x1F, "other pins untouched");
    pins::set_axis(&mut m, &AXIS_A, true);
    assert!((0..6).all(|p| field(&m, p) == PC_ALT3));
}
