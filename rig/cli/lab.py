"""``rig serve scope``: the virtual scope on the network for lab scripts (rig/lab/serve.py)."""
from __future__ import annotations

from pathlib import Path

from rig.cli.common import seed_arg, whole_number


def port_arg(text: str) -> int:
    """A TCP port: a whole number from 0 (a free one) to 65535."""
    return whole_number(text, 0, 65535, "a TCP port from 0 (a free one) to 65535")


def add_parsers(sub, command) -> None:
    """``rig serve scope`` (``command(sub, name, help, func)`` makes a subcommand)."""
    se = sub.add_parser("serve", help="serve a virtual instrument on the network (SCPI over VISA transports)")
    what = se.add_subparsers(dest="what", required=True)
    sc = command(what, "scope", "a scene's oscilloscope, answering SCPI as a Tektronix scope does", cmd_serve_scope)
    sc.add_argument("scene", help="a scene file, or a published scene's name (e.g. ptfe52_magnetic)")
    sc.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a scene key, as rig shot --set")
    sc.add_argument("--host", default="127.0.0.1",
                    help="the address to listen on (default 127.0.0.1, loopback; another only when named)")
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
    sc.add_argument("--log", metavar="FILE", help="append one line per connection, shot and refusal to FILE")


def cmd_serve_scope(args) -> None:
    """Serve until SIGINT/SIGTERM. With --json, the line naming the resources is JSON."""
    from rig.lab.serve import ServeSettings, serve

    settings = ServeSettings(scene=args.scene, overrides=tuple(args.set or ()), host=args.host, port=args.port,
                             hislip=args.hislip, vxi11=args.vxi11, personality=args.personality, idn=args.idn,
                             fire=args.fire, seed=args.seed, rig_port=args.rig_port,
                             out=Path(args.out) if args.out else None, log=Path(args.log) if args.log else None)
    serve(settings, say=lambda line: print(line, flush=True), as_json=args.json)
    args.json = False  # said as it served

