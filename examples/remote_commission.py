"""Commission an axis from a script, as a person would in the browser (issue 20).

Talks to `openmotion ui` through `openmotion.remote`: reads the machine, sets the axis's
end-limit response, switches the servo on, checks the switches by tripping +EL in the
simulator and watching the lamp, jogs with the deadman (the jog stops when the block ends),
homes, runs a move and reads what the scope recorded on the server.

Run: python examples/remote_commission.py [--url ws://127.0.0.1:8765/ws] [--token T]
(without --url it starts its own server on a free port and stops it at the end)
"""

from __future__ import annotations

import argparse
import time

from openmotion.remote import connect


def commission(url: str, token: str | None, axis: str = "x") -> dict[str, float]:
    with connect(url, token, timeout=30.0) as m:
        info = m.call("machine.info")
        ax = next(a for a in info["axes"] if a["name"] == axis)
        print(f"machine {info['name']!r}: axes {', '.join(a['name'] for a in info['axes'])};"
              f" {axis} in {ax['unit']}, max {ax['max_speed']:g} {ax['unit']}/s, "
              f"travel {ax['travel']}")
        res = m.call("interface.set", axis=axis, config_version=info["config_version"],
                     changes={"responses": {"el": "decel"}})
        print(f"end limits decelerate; saved to {res['saved'] or '(no machine file yet)'}")
        m.subscribe(rate_hz=20)
        m.call("axis.servo", axis=axis, on=True)

        def lamp(name: str) -> bool:
            return m.status["axes"][axis]["io"][name]

        m.call("sim.trip_limit", axis=axis, signal="pel", active=True)
        m.wait(lambda s: s["axes"][axis]["io"]["pel"], 10)
        print(f"+EL tripped in the simulator: lamp {'on' if lamp('pel') else 'OFF (check!)'}")
        m.call("sim.trip_limit", axis=axis, signal="pel", active=False)
        m.wait(lambda s: not s["axes"][axis]["io"]["pel"], 10)

        with m.jog(axis, +1, speed=10.0):
            time.sleep(0.5)
        m.wait(lambda s: s["axes"][axis]["state"] == "Standstill", 10)
        print(f"jogged to {m.status['axes'][axis]['position']:.3f} {ax['unit']}; released, "
              "it stopped")

        m.call("home.start", axis=axis)
        m.wait(lambda s: s["axes"][axis]["homing"]["state"] in ("done", "error"), 60)
        print(f"homing: {m.status['axes'][axis]['homing']['state']}")
        m.wait(lambda s: s["axes"][axis]["state"] == "Standstill", 10)

        m.call("scope.configure", channels=[f"{axis}.command", f"{axis}.velocity",
                                            f"{axis}.acceleration", f"{axis}.error"],
               seconds=10.0)
        m.call("axis.move", axis=axis, kind="relative", distance=20.0, max_vel=40.0,
               tacc=0.1, shape="S", vs_acc=10.0, vs_dec=10.0)
        m.wait(lambda s: s["axes"][axis]["moving"], 10)
        m.wait(lambda s: s["axes"][axis]["state"] == "Standstill"
               and not s["axes"][axis]["moving"], 30)
        data = m.call("scope.data", since=-1, max_points=100_000)
        v = data["columns"][f"{axis}.velocity"]
        a = data["columns"][f"{axis}.acceleration"]
        out = {"position": m.status["axes"][axis]["position"], "peak_velocity": max(v),
               "peak_acceleration": max(abs(x) for x in a), "samples": len(v)}
        print(f"move: now at {out['position']:.3f} {ax['unit']}, peak "
              f"{out['peak_velocity']:.2f} {ax['unit']}/s, "
              f"{out['peak_acceleration']:.1f} {ax['unit']}/s^2 "
              f"({out['samples']} scope samples at the control period)")
        return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--url", help="a running server's WebSocket, e.g. ws://127.0.0.1:8765/ws")
    ap.add_argument("--token")
    args = ap.parse_args()
    if args.url:
        commission(args.url, args.token)
        return 0
    from openmotion.remote.server import RemoteServer, ServerThread
    from openmotion.remote.service import MachineService

    svc = MachineService()
    svc.start()
    th = ServerThread(RemoteServer(svc)).start()
    try:
        commission(th.ws_url, None)
    finally:
        th.stop()
        svc.shutdown()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
