//! E-002: the simulated line answers a real master over raw Ethernet.
//!
//! Builds a private network namespace with one end of a veth pair, runs
//! `hil-sim serve` inside it, and drives it with ethercrab's std transport from
//! the other end. Needs root (CI runs as root); skipped with a message otherwise.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod common;

use common::Netns;
use ethercrab::{MainDevice, MainDeviceConfig, PduStorage, Timeouts};

/// One `serve` and master at a time: two debug-build simulators behind raw
/// sockets at once on a loaded 2-core machine miss ethercrab's PDU timeout.
static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// Holding [`ONE_AT_A_TIME`]: `hil-sim serve args` in a network namespace
/// (`tag` names its veth pair) and ethercrab's raw-socket master on the host
/// end. `None`, with a message that `test` is skipped, without root.
fn serve_and_master(
    test: &str,
    tag: char,
    args: &[&str],
) -> Option<(std::sync::MutexGuard<'static, ()>, Netns, MainDevice<'static>)> {
    let one = ONE_AT_A_TIME
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    if !common::is_root() {
        eprintln!("{test}: skipped, needs root for network namespaces and raw sockets");
        return None;
    }
    let net = Netns::new(env!("CARGO_BIN_EXE_hil-sim"), tag, args);
    let storage: &'static PduStorage<16, { PduStorage::element_size(1100) }> =
        Box::leak(Box::new(PduStorage::new()));
    let (tx, rx, pdu_loop) = storage.try_split().expect("split");
    let task = ethercrab::std::tx_rx_task(&net.host_if, tx, rx).expect("raw socket on the veth end");
    std::thread::spawn(move || futures_lite::future::block_on(task));
    // a debug-build simulator behind a raw socket on a loaded CI machine: roomy timeouts
    let timeouts = Timeouts {
        pdu: std::time::Duration::from_millis(500),
        eeprom: std::time::Duration::from_millis(500),
        mailbox_echo: std::time::Duration::from_millis(2000),
        mailbox_response: std::time::Duration::from_millis(2000),
        ..Timeouts::default()
    };
    Some((
        one,
        net,
        MainDevice::new(pdu_loop, timeouts, MainDeviceConfig::default()),
    ))
}

/// ethercrab's init over the veth pair: the line discovered, in Pre-Op.
async fn init(md: &MainDevice<'static>) -> ethercrab::SubDeviceGroup<4, 256> {
    md.init_single_group::<4, 256>(ethercrab::std::ethercat_now)
        .await
        .expect("init over veth")
}

#[test]
fn e002_raw_ethernet_veth_master_reaches_op() {
    let Some((_one, net, md)) = serve_and_master(
        "e002_raw_ethernet_veth",
        'v',
        &["--slaves", "2", "--seconds", "60"],
    ) else {
        return;
    };
    futures_lite::future::block_on(async {
        let group = init(&md).await;
        assert_eq!(group.len(), 2, "two simulated drives on the line");
        for sd in group.iter(&md) {
            assert_eq!(sd.identity().vendor_id, 0xB9);
        }
        let group = group.into_op(&md).await.expect("PRE-OP -> OP over veth");
        for _ in 0..20 {
            group.tx_rx(&md).await.expect("cycle");
        }
        for sd in group.iter(&md) {
            let (state, _) = sd.status().await.expect("status");
            assert_eq!(state, ethercrab::SubDeviceState::Op);
        }
        let group = group.into_safe_op(&md).await.expect("OP -> SAFE-OP");
        let group = group.into_pre_op(&md).await.expect("SAFE-OP -> PRE-OP");
        group.into_init(&md).await.expect("PRE-OP -> INIT").len()
    });
    drop(net);
}

/// `serve --axes 1` serves the single-axis device (issue 20): its product
/// code in the SII, no axis-B object (an SDO upload of 6841h is aborted
/// with 0602 0000h), only channel 1 mapped, Op with axis A's 23 + 29 bytes.
#[test]
fn e002_e005_serve_axes_1_is_the_single_axis_device() {
    use ethercrab::error::{CoeAbortCode, Error, MailboxError};
    let Some((_one, net, md)) =
        serve_and_master("e002_e005_serve_axes_1", 'w', &["--axes", "1", "--seconds", "60"])
    else {
        return;
    };
    futures_lite::future::block_on(async {
        let group = init(&md).await;
        assert_eq!(group.len(), 1);
        let sd = group.subdevice(&md, 0).expect("subdevice");
        assert_eq!(sd.identity().vendor_id, 0xB9);
        assert_eq!(sd.identity().product_id, drive_ecat::PRODUCT_CODE_SINGLE);
        for index in [0x6841u16, 0x6840] {
            match sd.sdo_read::<u16>(index, 0).await {
                Err(Error::Mailbox(MailboxError::Aborted { code, .. })) => {
                    assert_eq!(code, CoeAbortCode::NotFound, "{index:04X}h")
                }
                other => panic!("{index:04X}h: {other:?}"),
            }
        }
        let n: u8 = sd.sdo_read(0x1601, 0).await.expect("1601h:00");
        assert_eq!(n, 0, "channel 2 empty");
        let group = group.into_op(&md).await.expect("PRE-OP -> OP over veth");
        let sd = group.subdevice(&md, 0).expect("subdevice");
        assert_eq!(
            (sd.io_raw().outputs().len(), sd.io_raw().inputs().len()),
            (23, 29)
        );
        for _ in 0..20 {
            group.tx_rx(&md).await.expect("cycle");
        }
        let group = group.into_safe_op(&md).await.expect("OP -> SAFE-OP");
        let group = group.into_pre_op(&md).await.expect("SAFE-OP -> PRE-OP");
        group.into_init(&md).await.expect("PRE-OP -> INIT").len()
    });
    drop(net);
}
