"""Motion Creator in the browser, the rest of commissioning: repeat between two positions,
changes on the fly, set/reset positions, the homing drawing of the selected mode, the scope
trigger, tripping limits and alarms, simulation speed, single block and feed override.
"""

from __future__ import annotations

import pytest

import ui_browser
from ui_browser import after_pushes, field, goto, ready_axis, shot, status, wait_jogged, wait_status

server = ui_browser.server
page = ui_browser.page

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")


def motion(pg, **values: object) -> None:
    for name, v in values.items():
        form = "op-target" if name in ("mode", "position1", "position2", "distance", "velocity") \
            else "op-repeat" if name in ("delay_s", "count") else "op-motion"
        f = field(pg, form, name)
        if name in ("mode", "shape"):
            f.select_option(str(v))
        else:
            f.fill(str(v))


def test_repeat_between_two_positions_with_a_delay(page):
    ready_axis(page, "z")
    motion(page, mode="absolute", position1=1, position2=3, max_vel=20, tacc=0.05, tdec=0.05,
           delay_s=1.0, count=3)
    page.check("#op-repeat [data-name='repeat'] input")
    # what the page is told while it repeats, recorded on the page (each rest lasts 1 s)
    page.evaluate("""() => {
        window.__rep = { rested: [], shown: false };
        window.openmotion.addEventListener('status', () => {
            const a = window.openmotion.status.axes.z, r = window.__rep;
            if (a.repeat && document.querySelector('#op-state').innerText.includes('(repeat)'))
                r.shown = true;
            const at = Math.round(a.position * 1e6) / 1e6;
            if (a.repeat && !a.moving && (at === 1 || at === 3) && r.rested.at(-1) !== at)
                r.rested.push(at);
        });
    }""")
    page.click("#op-play1")
    # three moves (1, 3, 1), resting between them; then the repeat ends by itself at 1
    wait_status(page, "!s.axes.z.repeat && !s.axes.z.moving"
                " && Math.abs(s.axes.z.position - 1) < 1e-6"
                " && window.__rep.rested.includes(3)", 30)
    rep = page.evaluate("window.__rep")
    assert rep["shown"], rep
    assert rep["rested"][:2] == [1, 3], rep      # it visited both ends, resting at each
    page.uncheck("#op-repeat [data-name='repeat'] input")


def test_change_speed_and_position_on_the_fly_then_stop(page):
    ready_axis(page, "x")
    page.click("#op-reset-position")
    wait_status(page, "s.axes.x.command === 0 && s.axes.x.target === 0", 5)
    motion(page, mode="velocity", velocity=10, max_vel=50, tacc=0.05)
    page.click("#op-play2")
    wait_status(page, "Math.abs(s.axes.x.velocity - 10) < 1e-6", 5)
    field(page, "op-target", "velocity").fill("25")
    page.click("#op-vchange")
    wait_status(page, "Math.abs(s.axes.x.velocity - 25) < 1e-6", 5)
    page.click("#op-stop")
    wait_status(page, "!s.axes.x.moving && s.axes.x.velocity === 0", 5)
    # a positioning move retargeted on the fly ends on the new target
    here = status(page, "s.axes.x.position")
    motion(page, mode="absolute", position1=here + 40, position2=here + 15, max_vel=10,
           tacc=0.05, tdec=0.05)    # 4 s of motion: long enough to be seen moving
    page.click("#op-play1")
    wait_status(page, "s.axes.x.moving && s.axes.x.velocity > 0", 5)
    page.click("#op-pchange")
    wait_status(page, "!s.axes.x.moving", 10)
    assert abs(status(page, "s.axes.x.position") - (here + 15)) < 1e-6
    # set and reset the counters
    field(page, "op-setpos", "position").fill("12.5")
    page.click("#op-set-position")
    wait_status(page, "s.axes.x.command === 12500 && s.axes.x.feedback === 12500", 5)
    page.click("#op-reset-position")
    wait_status(page, "s.axes.x.command === 0 && s.axes.x.feedback === 0", 5)


def test_the_homing_drawing_follows_the_selected_mode(page):
    ready_axis(page, "y")
    goto(page, "homing")
    page.wait_for_selector("#home-drawing")
    field(page, "home-fields", "mode").select_option("11")
    page.wait_for_function("() => document.querySelector('#home-seq-note').children.length === 3")
    note = page.inner_text("#home-seq-note")
    assert "EZ" in note and "ORG" in note and "home mark" in note
    arrows = page.locator("#home-drawing line[marker-end]").count()
    assert arrows == 4          # three phases and the final move to the mark
    shot(page, "homing")
    field(page, "home-fields", "mode").select_option("0")
    page.wait_for_function("() => document.querySelector('#home-seq-note').children.length === 1")
    # an invalid speed is refused beside its field, nothing saved
    field(page, "home-fields", "str_vel").fill("1e9")
    assert "must be <=" in page.inner_text("#home-fields [data-name='str_vel'] .field-error")
    field(page, "home-fields", "str_vel").fill("5")


def test_scope_trigger_captures_a_move(page):
    ready_axis(page, "x")
    goto(page, "scope")
    page.wait_for_selector("#scope-apply")
    field(page, "scope-trig", "mode").select_option("single")
    field(page, "scope-trig", "channel").select_option("x.velocity")
    field(page, "scope-trig", "edge").select_option("rising")
    field(page, "scope-trig", "level").fill("5")
    field(page, "scope-trig", "pre_s").fill("0.2")
    field(page, "scope-cfg", "seconds").fill("2")
    page.click("#scope-apply")
    scope_state(page, "s.trigger.mode === 'rising' && s.seconds === 2")
    page.click("#scope-arm")
    scope_state(page, "s.trigger.mode === 'rising' && s.running && s.triggered_at === null")
    goto(page, "operation")
    motion(page, mode="relative", distance=10, max_vel=30, tacc=0.05, tdec=0.05)
    page.click("#op-play2")
    wait_status(page, "!s.axes.x.moving", 10)
    goto(page, "scope")
    page.wait_for_selector("#scope-info:has-text('triggered at')", timeout=30_000)
    t = page.evaluate("window.openmotion.scopeChart.t")
    assert t[-1] - t[0] <= 2.0 + 1e-6
    # back to free run
    field(page, "scope-trig", "mode").select_option("off")
    field(page, "scope-cfg", "seconds").fill("30")
    page.click("#scope-apply")
    scope_state(page, "s.trigger.mode === 'none' && s.seconds === 30")
    page.click("#scope-run")


def scope_state(pg, cond: str) -> None:
    """Wait until the server's scope settings (`scope.get`, as `s`) satisfy `cond`."""
    pg.wait_for_function(f"""async () => {{
        const s = await window.openmotion.call('scope.get', {{}}, {{ quiet: true }});
        return Boolean({cond});
    }}""", timeout=30_000, polling=200)


def test_simulation_trips_a_limit_and_an_alarm_and_runs_faster(page):
    ready_axis(page, "y")
    motion(page, mode="velocity", velocity=10, max_vel=20, tacc=0.05)
    page.click("#op-play2")
    wait_status(page, "s.axes.y.velocity > 0", 5)
    goto(page, "simulation")
    page.click("#sim-y-pel")
    wait_status(page, "s.axes.y.io.pel && !s.axes.y.moving && s.axes.y.velocity === 0", 5)
    assert page.get_attribute("#sim-y-lamp-pel", "data-on") == "true"
    page.click("#sim-y-pel")
    wait_status(page, "!s.axes.y.io.pel", 5)
    page.click("#sim-y-alm")
    wait_status(page, "s.axes.y.io.alm && s.axes.y.state === 'ErrorStop'", 5)
    page.click("#sim-y-alm")
    wait_status(page, "!s.axes.y.io.alm", 5)
    page.click("#sim-reset")
    wait_status(page, "s.axes.y.state !== 'ErrorStop'", 5)
    # a general input switched from the page reaches the board and its lamp
    level = bool(status(page, "s.board.di[3]"))
    page.click("#sim-di-3")
    wait_status(page, f"s.board.di[3] === {str(not level).lower()}", 5)
    page.wait_for_selector(f"#sim-di-lamp-3[data-on={str(not level).lower()}]")
    page.click("#sim-di-3")
    wait_status(page, f"s.board.di[3] === {str(level).lower()}", 5)
    # a typed factor survives the pushes until Apply (they used to put the old one back)
    field(page, "sim-speed", "factor").fill("5")
    page.focus("#sim-reset")
    after_pushes(page)
    assert field(page, "sim-speed", "factor").input_value() == "5"
    page.click("#sim-speed-apply")
    wait_status(page, "s.speed === 5", 5)
    # the factor reached the controller and its time goes on (how much faster than the
    # wall a loaded machine runs is a figure for bench/bench_ui.py, not a test)
    t0 = status(page, "s.time")
    wait_status(page, f"s.time - {t0} > 5.0", 60)
    page.click("#sim-speed-1")
    wait_status(page, "s.speed === 1", 5)
    field(page, "sim-speed", "factor").fill("50")
    assert "must be <= 20" in page.inner_text("#sim-speed [data-name='factor'] .field-error")


PROGRAM = "G21 G90\nG0 X0 Y0\nG1 F600 X5\nG1 Y5\nG1 X0\nG1 Y0\nM30\n"


def test_single_block_and_feed_override(page):
    ready_axis(page)
    goto(page, "program")
    page.click("#prog-servo-all")
    wait_status(page, "Object.values(s.axes).every((a) => a.servo)", 5)
    page.fill("#prog-text", PROGRAM)
    page.click("#prog-load-text")
    page.wait_for_selector("#prog-loaded:has-text('7 lines')", timeout=30_000)
    page.check("#prog-single")
    # the setting reaches the server at once and the box keeps it once the focus has left
    # it (it used to follow the server's old value on the next push: a Run clicked then
    # ran the whole program without a stop)
    wait_status(page, "s.program.single_block")
    page.focus("#prog-listing")
    after_pushes(page)
    assert page.is_checked("#prog-single")
    page.click("#prog-run-btn")
    wait_status(page, "s.program.state === 'paused' && s.program.line >= 2", 10)
    first = status(page, "s.program.line")
    page.click("#prog-resume")
    wait_status(page, f"s.program.state === 'paused' && s.program.line > {first}", 10)
    page.uncheck("#prog-single")
    wait_status(page, "!s.program.single_block", 5)
    page.eval_on_selector("#prog-ovr",
                          "(e) => { e.value = 150; e.dispatchEvent(new Event('input')); }")
    wait_status(page, "s.program.feed_override === 150", 5)
    page.click("#prog-resume")
    wait_status(page, "s.program.state === 'done'", 20)


LASER = "G21 G90\nG0 X0 Y0\nM62 P0\nG1 F900 X6\nM63 P0\nG1 Y6\nM62 P0\nG1 X0\nM63 P0\nM30\n"


def test_path_marks_the_output_firings_and_keyboard_jog_survives_a_job(page):
    ready_axis(page)
    goto(page, "program")
    page.click("#prog-servo-all")
    wait_status(page, "Object.values(s.axes).every((a) => a.servo)", 5)
    page.fill("#prog-text", LASER)
    page.click("#prog-load-text")
    page.wait_for_selector("#prog-loaded:has-text('10 lines')", timeout=30_000)
    page.click("#prog-run-btn")
    wait_status(page, "s.program.state === 'done'", 30)
    goto(page, "path")
    # four switchings; the first (M62 before any motion) is sometimes not in the path's record
    # (noted for remote), so at least the three during motion
    page.wait_for_function("() => window.openmotion.pathView.markers.length >= 3", timeout=30_000)
    assert "firings" in page.inner_text("#path-info")
    # keyboard jog still works after the job (a known complaint against other senders)
    goto(page, "operation")
    if not page.is_checked("#op-keyboard"):
        page.check("#op-keyboard")
    page.locator("#op-chart").click()
    here = status(page, "s.axes.x.position")
    page.keyboard.down("ArrowRight")
    wait_jogged(page, "x", here, +1)
    page.keyboard.up("ArrowRight")
    wait_status(page, "s.axes.x.velocity === 0 && !s.axes.x.moving", 3)


def test_a_second_tab_is_told_to_reload_and_sees_the_scope_history(page, browser, server):
    other = browser.new_context().new_page()
    other.goto(server.url + "#interface")
    other.wait_for_selector("#conn[data-state=open]")
    other.wait_for_selector("#if-save")
    # this tab changes a setting: the other one is told, and its own change is refused
    goto(page, "interface")
    page.wait_for_selector("#if-save")
    width = field(page, "if-pulse", "pulse_width_us")
    width.fill("3" if width.input_value() != "3" else "4")
    page.click("#if-save")
    page.wait_for_selector("#if-saved:has-text('applied'), #if-saved:has-text('saved to')")
    other.wait_for_selector("#reload-banner:not([hidden])", timeout=20_000)
    w2 = field(other, "if-pulse", "pulse_width_us")
    w2.fill("9")
    other.click("#if-save")
    other.wait_for_selector("#if-error:has-text('reload')", timeout=20_000)
    other.click("#reload-config")
    other.wait_for_selector("#reload-banner[hidden]", state="attached")
    other.wait_for_function("() => window.openmotion.configVersion === "
                            "window.openmotion.status.config_version", timeout=30_000)
    # the page shows the reloaded settings (the form is rebuilt when its interface read
    # answers, after the version): the refused "9" is gone; a value typed before that
    # would be overwritten by the rebuild
    other.wait_for_function(
        "() => { const e = document.querySelector("
        "\"#if-pulse [data-name='pulse_width_us'] input\"); return e && e.value !== '9'; }",
        timeout=30_000)
    field(other, "if-pulse", "pulse_width_us").fill("9")
    other.click("#if-save")
    other.wait_for_selector("#if-saved:has-text('applied'), #if-saved:has-text('saved to')",
                            timeout=20_000)
    # now the first tab is the stale one: it reloads, then its commands go through
    page.wait_for_selector("#reload-banner:not([hidden])", timeout=20_000)
    page.click("#reload-config")
    page.wait_for_function("() => window.openmotion.configVersion === "
                           "window.openmotion.status.config_version")
    # the scope history lives on the server: the other tab draws the same samples
    ready_axis(page)
    field(page, "op-target", "mode").select_option("relative")
    field(page, "op-target", "distance").fill("5")
    before = status(page, "s.axes.x.command")
    page.click("#op-play2")
    wait_status(page, f"s.axes.x.command === {before + 5000} && !s.axes.x.moving", 10)
    goto(other, "scope")
    other.wait_for_function("() => (window.openmotion.scopeChart || {t: []}).t.length > 1000",
                            timeout=30_000)
    t_other = other.evaluate("window.openmotion.scopeChart.t[0]")
    assert t_other < status(page, "s.time") - 1.0   # history from before the tab opened it
    other.context.close()


def test_a_reload_answered_late_leaves_no_stale_banner(page):
    """The reload banner's check runs 700 ms after a stale status; a reload whose
    machine.info answer takes longer (a loaded machine) must not end with the banner shown
    by a check that compared with the version from before the reload."""
    page.evaluate("""() => {
        const a = window.openmotion, call = a.rpc.call.bind(a.rpc);
        a.configVersion -= 1;          // this tab is one version behind: the pushes say so
        a.rpc.call = async (method, params, opts) => {
            if (method === 'machine.info') await new Promise((r) => setTimeout(r, 1500));
            return call(method, params, opts);
        };
    }""")
    page.wait_for_selector("#reload-banner:not([hidden])")
    page.click("#reload-config")
    page.wait_for_function("() => { const a = window.openmotion; return !a._staleTimer"
                           " && a.configVersion === a.status.config_version; }")
    assert page.is_hidden("#reload-banner")


def test_a_jog_stops_when_the_connection_drops(page):
    ready_axis(page)
    plus = page.locator("#op-jog-plus").bounding_box()
    page.mouse.move(plus["x"] + plus["width"] / 2, plus["y"] + plus["height"] / 2)
    here = status(page, "s.axes.x.position")
    page.mouse.down()
    wait_jogged(page, "x", here, +1)
    page.evaluate("window.openmotion.rpc.ws.close()")      # the button is still held
    page.wait_for_selector("#conn[data-state=open]", timeout=30_000)
    wait_status(page, "s.axes.x.velocity === 0 && !s.axes.x.moving", 5)
    page.wait_for_timeout(300)
    assert status(page, "s.axes.x.velocity") == 0            # and it does not start again
    page.mouse.up()


def test_scope_pause_freezes_the_recording_and_run_resumes_it(page):
    goto(page, "scope")
    page.wait_for_function("() => (window.openmotion.scopeChart || {t: []}).t.length > 10",
                           timeout=30_000)
    page.click("#scope-pause")
    page.wait_for_selector("#log:has-text('paused')")
    # pushes already on their way may still arrive: wait until the chart stops growing
    # (one second without a sample), then it must stay still
    page.wait_for_function("""() => {
        const n = window.openmotion.scopeChart.t.length, now = performance.now();
        const w = window.__still || (window.__still = { n, since: now });
        if (w.n !== n) { w.n = n; w.since = now; }
        return now - w.since > 1000;
    }""", timeout=30_000, polling=100)
    n = page.evaluate("window.openmotion.scopeChart.t.length")
    page.wait_for_timeout(800)
    assert page.evaluate("window.openmotion.scopeChart.t.length") == n
    page.click("#scope-run")
    page.wait_for_selector("#log:has-text('running')")
    page.wait_for_function(f"() => window.openmotion.scopeChart.t.length > {n}", timeout=20_000)


def test_the_page_logic_in_the_browser(page):
    """The pure parts of the front end: field rules, error placement, decimation, diffs."""
    out = page.evaluate("""async () => {
        const f = await import('/static/js/fields.js');
        const v = await import('/static/js/view3d.js');
        const a = await import('/static/js/app.js');
        const spec = {name: 'max_vel', label: 'MaxVel', unit: 'mm/s', min: 0, minExclusive: true,
                      max: 500};
        const xs = [], ys = [], zs = [];
        for (let i = 0; i <= 1000; i++) { xs.push(i * 0.001); ys.push(0); zs.push(0); }
        const idx = v.decimate(xs, ys, zs, 0.01, null);
        const snap = {axes: {x: {command: 1, io: {inp: true, org: false}}}, estop: false};
        a.mergeDiff(snap, {axes: {x: {io: {inp: false}, fault: null}}, estop: true});
        return {
            ok: f.parseField(spec, '12.5'), zero: f.parseField(spec, '0'),
            big: f.parseField(spec, '501'), text: f.parseField(spec, '1,5'),
            exp: f.parseField(spec, '1e2'), empty: f.parseField(spec, ''),
            int: f.parseField({name: 'n', label: 'N', kind: 'int'}, '2.5'),
            param: f.findParam({data: {param: 'changes.logic.pel'}}, ['logic.pel', 'pel']),
            msg: f.findParam({message: 'str_vel must be <= max_vel'}, ['max_vel', 'str_vel']),
            none: f.findParam({message: 'axis z: disabled'}, ['max_vel']),
            idx: [idx.length, idx[0], idx[idx.length - 1]], snap,
        };
    }""")
    assert out["ok"] == [12.5, ""]
    assert out["zero"][1] == "MaxVel must be > 0 mm/s"
    assert out["big"][1] == "MaxVel must be <= 500 mm/s"
    assert out["text"][1] == "MaxVel must be a number"
    assert out["exp"] == [100, ""]
    assert out["empty"][1] == "MaxVel is required"
    assert out["int"][1] == "N must be a whole number"
    assert out["param"] == "logic.pel"
    assert out["msg"] == "str_vel"
    assert out["none"] is None
    n, first, last = out["idx"]
    assert first == 0 and last == 1000 and 95 <= n <= 110     # one point per 0.01 of 1.0
    assert out["snap"] == {"axes": {"x": {"command": 1, "io": {"inp": False, "org": False},
                                          "fault": None}}, "estop": True}


def test_escape_stops_every_axis_decelerating_and_f1_is_the_estop(page):
    ready_axis(page, "z")
    field(page, "op-target", "mode").select_option("velocity")
    field(page, "op-target", "velocity").fill("5")
    page.click("#op-play2")
    wait_status(page, "s.axes.z.velocity > 0", 5)
    page.keyboard.press("Escape")
    wait_status(page, "!s.axes.z.moving && s.axes.z.velocity === 0", 5)
    assert status(page, "s.axes.z.state") == "Standstill"      # a stop, not an ErrorStop
    page.click("#op-play2")
    wait_status(page, "s.axes.z.velocity > 0", 5)
    page.keyboard.press("F1")
    wait_status(page, "!s.axes.z.moving && s.axes.z.state === 'ErrorStop'", 5)
    page.click("#estop-reset")
    wait_status(page, "Object.values(s.axes).every((a) => a.state !== 'ErrorStop')", 5)
