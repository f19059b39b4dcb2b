//! A test device for the agent's tests and fuzz targets (feature `testing`,
//! never in a product image; gated as `profinet::testing` is): the device
//! data the unit tests check the MIB view against, and the device the `snmp`
//! fuzz target answers for.
//!
//! `no_std` and heap-free like the agent: every value is a constant.

use crate::{Delays, Device, LldpAgent, LldpStats, LocalPort, MacPhy, ManAddr, Neighbor, Pno, RxStats};

/// The local ports as the LLDP transmitter describes them: port 1 up (100BASE-TX FD), port 2
/// down (MAU type 0), auto-negotiation supported and on, 10/100 half/full advertised.
pub fn local_ports() -> [LocalPort; 2] {
    let port = |tx, mau_type| LocalPort {
        pno: Pno {
            delay: Delays { line: 0, tx, rx: 7 },
            rt2: 0,
            rt3: 0,
        },
        mac_phy: MacPhy {
            autoneg: 3,
            advertised: [0x6c, 0x00],
            mau_type,
        },
    };
    [port(11, 16), port(12, 0)]
}

/// The test device: named `drive-1` at 192.168.0.50, port 1 with a neighbour that sent the
/// PROFINET, MAC/PHY and management address TLVs, port 2 with none; the ports as
/// [`local_ports`], LLDP statistics with some of every counter.
pub fn device() -> Device<'static> {
    Device {
        descr: b"drive",
        uptime_cs: 4242,
        macs: [[2, 0, 0, 0, 0, 1], [2, 0, 0, 0, 0, 2], [2, 0, 0, 0, 0, 3]],
        links: [true, false],
        neighbors: [
            Some(Neighbor {
                chassis_subtype: 4,
                chassis_id: b"plc",
                port_subtype: 7,
                port_id: b"port-003",
                sys_name: b"plc",
                pno: Some(Pno {
                    delay: Delays {
                        line: 55,
                        tx: 1123,
                        rx: 444,
                    },
                    rt2: 2,
                    rt3: 0,
                }),
                mac_phy: Some(MacPhy {
                    autoneg: 1,
                    advertised: [0x04, 0x00],
                    mau_type: 30,
                }),
                man_addr: Some(ManAddr {
                    ipv4: [10, 0, 0, 1],
                    if_subtype: 3,
                    if_id: 9,
                }),
            }),
            None,
        ],
        name_of_station: b"drive-1",
        man_addr: Some(ManAddr {
            ipv4: [192, 168, 0, 50],
            if_subtype: 2,
            if_id: 1,
        }),
        man_addr_ports: [0xc0],
        ports: local_ports(),
        lldp: LldpAgent {
            tx_interval: 5,
            hold: 4,
            reinit_delay: 2,
            tx_delay: 1,
            notification_interval: 5,
            tlvs_tx: 0,
            stats: LldpStats {
                last_change_cs: 1200,
                inserts: 3,
                deletes: 1,
                drops: 0,
                ageouts: 1,
                tx: [17, 0],
                rx: [
                    RxStats {
                        discarded: 2,
                        errors: 2,
                        frames: 9,
                        tlvs_discarded: 0,
                        tlvs_unrecognized: 4,
                        ageouts: 1,
                    },
                    RxStats::default(),
                ],
            },
        },
    }
}
