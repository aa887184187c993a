"""`openmotion ui`: serve the machine to the browser front end and to scripts."""

from __future__ import annotations

import argparse
import sys
import time

from ..errors import MotionError

DEFAULT_PORT = 8765


def add_parser(sub: argparse._SubParsersAction, formatter: type) -> None:
    """Register the `ui` subcommand (cli.py calls this with one line)."""
    u = sub.add_parser("ui", formatter_class=formatter,
                       help="serve the machine in the browser (Motion Creator) and to "
                       "scripts over JSON-RPC (docs/remote.md)")
    u.add_argument("--machine", help="TOML machine file to run and to save settings into "
                   "(default: the XYZU table, in memory)")
    u.add_argument("--port", type=int, default=DEFAULT_PORT, help="TCP port (0 = any free)")
    u.add_argument("--host", default="127.0.0.1",
                   help="bind address; any other than 127.0.0.1 needs --token")
    u.add_argument("--token", help="shared secret every request must carry (>= 16 chars)")
    u.add_argument("--workdir", help="the only folder whose files program.load / "
                   "machine.load / machine.save may use (default with --host: the machine "
                   "file's folder; on 127.0.0.1 without it: any path)")
    u.add_argument("--speed", type=float, default=1.0,
                   help="simulation speed: 1 = real time, up to 20 = faster")
    u.set_defaults(handler=cmd_ui)


def cmd_ui(args: argparse.Namespace) -> int:
    from .server import RemoteServer, ServerThread, check_bind
    from .service import MachineService
    from .workdir import WorkFolder

    if isinstance(args.port, bool) or not 0 <= args.port <= 65535:
        raise MotionError(f"--port must be in [0, 65535], got {args.port!r}")
    check_bind(args.host, args.token)
    workdir = WorkFolder.for_server(args.host, args.workdir, args.machine)
    svc = MachineService(file=args.machine, speed=args.speed, workdir=workdir)
    server = RemoteServer(svc, token=args.token)
    svc.start()
    thread = ServerThread(server, args.host, args.port)
    try:
        thread.start()
    except MotionError:
        svc.shutdown()
        raise MotionError(f"--port {args.port}: cannot listen on {args.host} (in use?)"
                          ) from None
    query = f"?token={args.token}" if args.token else ""
    print(f"openmotion ui: http://{args.host}:{thread.port}/{query}")
    print(f"  machine '{svc.config.name}' ({len(svc.ctl.axes)} axes), "
          f"{'file ' + str(svc.file) if svc.file else 'in memory'}; "
          f"API ws://{args.host}:{thread.port}/ws; Ctrl-C stops", file=sys.stderr)
    try:
        while thread._thread.is_alive():
            # not join(0.5): a Ctrl-C inside Thread.join leaves the thread marked ended, so
            # thread.stop() below returned at once and uvicorn was still running at exit
            time.sleep(0.5)
    except KeyboardInterrupt:
        print("openmotion ui: stopping the axes and the server", file=sys.stderr)
    finally:
        svc.shutdown()
        thread.stop()
    return 0
