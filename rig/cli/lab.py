"""``rig serve scope``: the virtual scope on the network for lab scripts (rig/lab/serve.py)."""
from __future__ import annotations

import argparse
from pathlib import Path

from rig.cli.common import plain, seed_arg, whole_number

# the wire's limits (instruments.transports.wire.Limits' defaults; tests/lab/test_serve.py checks they agree)
IDLE_TIMEOUT_S, HALF_OPEN_TIMEOUT_S, STALL_TIMEOUT_S, MAX_CLIENTS = 300.0, 10.0, 10.0, 32


def port_arg(text: str) -> int:
    """A TCP port: a whole number from 0 (a free one) to 65535."""
    return whole_number(text, 0, 65535, "a TCP port from 0 (a free one) to 65535")


def clients_arg(text: str) -> int:
    """A number of connections: a whole number from 1 to 4096."""
    return whole_number(text, 1, 4096, "a whole number of connections from 1 to 4096")


def seconds_arg(zero: str | None = None):
    """An argparse type: seconds > 0 and at most a day; 0 too when ``zero`` says what it means."""
    allowed = f"seconds from 0 ({zero}) to 86400" if zero else "seconds > 0, at most 86400"

    def parse(text: str) -> float:
        value = plain(float)(text)
        if not (0 <= value <= 86400 if zero else 0 < value <= 86400):
            raise argparse.ArgumentTypeError(f"{text!r}: {allowed}")
        return value

    parse.__name__ = "seconds"
    return parse


def add_parsers(sub, command) -> None:
    """``rig serve scope`` (``command(sub, name, help, func)`` makes a subcommand)."""
    se = sub.add_parser("serve", help="serve a virtual instrument on the network (SCPI over VISA transports)")
    what = se.add_subparsers(dest="what", required=True)
    sc = command(what, "scope", "a scene's oscilloscope, answering SCPI as a Tektronix scope does", cmd_serve_scope)
    sc.add_argument("scene", help="a scene file, or a published scene's name (e.g. ptfe52_magnetic)")
    sc.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a scene key, as rig shot --set")
    sc.add_argument("--host", default="127.0.0.1",
                    help="the address to listen on (default 127.0.0.1, loopback; another only when named, with a "
                         "warning: the instrument has no authentication; IPv6 too, e.g. ::1)")
    sc.add_argument("--port", type=port_arg, default=4000, help="raw-socket SCPI port (default 4000; 0: a free one)")
    sc.add_argument("--hislip", type=port_arg, metavar="PORT",
                    help="also serve HiSLIP on PORT (4880 is its own; 0: a free one)")
    sc.add_argument("--vxi11", action="store_true",
                    help="also serve VXI-11 (registered with the portmapper on port 111, started where none runs)")
    sc.add_argument("--personality", default="tds2000", choices=["tds2000", "mdo3000", "mso4"],
                    help="which scope's replies: tds2000 (TDS2024C, 2,500 points, 8 bit), mdo3000, mso4 (16 bit)")
    sc.add_argument("--idn", metavar="TEXT", help='the *IDN? reply to claim, e.g. "TEKTRONIX,MSO44,C012345,CF:91.1CT '
                                                  'FV:2.0.3.950" (tm_devices needs a model it knows)')
    sc.add_argument("--fire", default="on-arm", metavar="on-arm|on-command|every=SECONDS",
                    help="when a shot is fired: on-arm (ACQuire:STATE ON; default), on-command (armed, the shot "
                         "waits for TRIGger FORCe, *TRG or RIG:FIRE), every=SECONDS (armed, a shot every SECONDS)")
    sc.add_argument("--seed", type=seed_arg, help="the first shot's seed (the warm-up shot, which the scope "
                                                  "holds as its first record); the k-th shot uses SEED+k-1 "
                                                  "(default: a fresh one, printed)")
    sc.add_argument("--rig-port", type=port_arg, metavar="PORT",
                    help="serve the RIG: commands (striker, magnet, seed, fire) alone on PORT too (0: a free one)")
    sc.add_argument("--out", metavar="ARCHIVE.h5", help="append every shot, with its settings, to an HDF5 archive")
    sc.add_argument("--log", metavar="FILE", help="append one line per listener, connection, disconnect, refusal, "
                                                  "protocol violation, refused command, shot and refused shot to FILE")
    sc.add_argument("--idle-timeout", type=seconds_arg("never"), default=IDLE_TIMEOUT_S, metavar="SECONDS",
                    help="close a connection that sends nothing for SECONDS while none of its requests is in "
                         f"progress (default {IDLE_TIMEOUT_S:g}; 0: never)")
    sc.add_argument("--half-open-timeout", type=seconds_arg(), default=HALF_OPEN_TIMEOUT_S, metavar="SECONDS",
                    help="close a connection whose opening (HiSLIP's Initialize and AsyncInitialize) is not "
                         f"complete after SECONDS (default {HALF_OPEN_TIMEOUT_S:g})")
    sc.add_argument("--stall-timeout", type=seconds_arg(), default=STALL_TIMEOUT_S, metavar="SECONDS",
                    help="end a message begun whose bytes stop for SECONDS, and a reply not taken for as long "
                         f"(default {STALL_TIMEOUT_S:g})")
    sc.add_argument("--max-clients", type=clients_arg, default=MAX_CLIENTS, metavar="N",
                    help=f"connections (HiSLIP: sessions) each transport takes at once (default {MAX_CLIENTS})")
    sc.add_argument("--per-address", type=clients_arg, metavar="N",
                    help="connections one address other than loopback may hold (default: half of --max-clients)")


def cmd_serve_scope(args) -> None:
    """Serve until SIGINT/SIGTERM. With --json, the line naming the resources is JSON."""
    from instruments.transports.wire import Limits
    from rig.errors import invalid
    from rig.lab.serve import ServeSettings, serve

    if args.per_address is not None and args.per_address > args.max_clients:
        raise invalid("--per-address", args.per_address, f"a whole number from 1 to --max-clients ({args.max_clients})")
    limits = Limits(max_clients=args.max_clients, per_address=args.per_address, idle_timeout_s=args.idle_timeout,
                    half_open_timeout_s=args.half_open_timeout, stall_timeout_s=args.stall_timeout)
    settings = ServeSettings(scene=args.scene, overrides=tuple(args.set or ()), host=args.host, port=args.port,
                             hislip=args.hislip, vxi11=args.vxi11, personality=args.personality, idn=args.idn,
                             fire=args.fire, seed=args.seed, rig_port=args.rig_port,
                             out=Path(args.out) if args.out else None, log=Path(args.log) if args.log else None,
                             limits=limits)
    serve(settings, say=lambda line: print(line, flush=True), as_json=args.json)
    args.json = False  # said as it served

