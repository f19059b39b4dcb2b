"""The command line the controller scripts share (controller.py on
profinet-py, tia.py on scapy, fb.py's scenarios): no import beyond argparse,
so that every one of their pythons can load it."""


def device_arguments(ap, name="drive-1", ip="192.168.0.50"):
    """Adds to the argparse parser `ap` serve's interface and device, the
    GSDML and its modules for slots 1 and 2, and the name and IP the script
    gives the device (`name`, `ip` by default); returns `ap`."""
    ap.add_argument("--iface", required=True)
    ap.add_argument("--device-mac", required=True)
    ap.add_argument("--gsdml", required=True)
    ap.add_argument("--out-module", required=True, help="GSDML module ID for slot 1")
    ap.add_argument("--in-module", required=True, help="GSDML module ID for slot 2")
    ap.add_argument("--name", default=name)
    ap.add_argument("--ip", default=ip)
    return ap
