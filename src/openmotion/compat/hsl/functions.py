"""The function table: every HSL function the library offers, where its name and argument
order come from, and its status (docs/porting-hsl.md is generated from it, tests check it).

origin: "manual" (named in the HSL-4XMO manual), "header" (the real library's header,
seed-facts 2.2), "ours" (no vendor source: our name and arguments).
order: "manual" (an example in the manual shows the arguments), "header", "ours".
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Entry:
    name: str
    group: str
    origin: str
    order: str
    status: str = "done"
    note: str = ""


_M, _H, _O = "manual", "header", "ours"


def _e(name: str, group: str, origin: str = _M, order: str = _H, note: str = "") -> Entry:
    return Entry(name, group, origin, order, "done", note)


TABLE: tuple[Entry, ...] = (
    # system and addressing
    _e("HSL_initial", "system", _H, _H, "opens card 0's network"),
    _e("HSL_close", "system", _H, _H, "stops every axis at once"),
    _e("HSL_get_module_count", "system", _O, _O),
    _e("HSL_get_connect_index", "system", _O, _O),
    _e("HSL_connect_status", "system", _H, _O, "(card_ID, slave_ID) -> 1/0"),
    _e("HSL_get_scan_time", "system", _O, _O, "Table 4-1 formula"),
    _e("HSL_get_time", "system", _O, _O, "virtual network time"),
    _e("HSL_M_get_axis_no", "system", _O, _O, "Table 4-5"),
    _e("HSL_M_get_axis_location", "system", _O, _O, "Table 4-5"),
    _e("HSL_M_version_info", "system", _M, _O, "(hardware, firmware, library)"),
    _e("HSL_M_config_from_file", "system", _M, _O, "reads a network file, not an INI"),
    _e("HSL_M_get_error_message", "system", _O, _O, "codes are ours"),
    # velocity mode and stops
    _e("HSL_M_tv_move", "velocity", order=_M, note="4.10 example"),
    _e("HSL_M_start_tv_move", "velocity", order=_M, note="4.10 spelling of tv_move"),
    _e("HSL_M_sv_move", "velocity"),
    _e("HSL_M_start_sv_move", "velocity", note="5.3 spelling of sv_move"),
    _e("HSL_M_v_change", "velocity", order=_M, note="Table 4-6"),
    _e("HSL_M_cmp_v_change", "velocity", note="(axis, NewVel, Tacc) as v_change"),
    _e("HSL_M_sd_stop", "velocity"),
    _e("HSL_M_emg_stop", "velocity"),
    _e("HSL_M_get_current_speed", "velocity"),
    _e("HSL_M_get_currebt_speed", "velocity", note="the manual's misspelling (4.11)"),
    _e("HSL_M_fix_speed_range", "speed range", order=_M, note="4.6 example"),
    _e("HSL_M_unfix_speed_range", "speed range"),
    _e("HSL_M_verify_speed", "speed range", note="returns (min vel, minAccT, maxAccT)"),
    # point to point
    _e("HSL_M_start_tr_move", "point to point", order=_M, note="4.6, 4.11 examples"),
    _e("HSL_M_start_ta_move", "point to point", order=_M, note="Table 4-7 example"),
    _e("HSL_M_start_sr_move", "point to point"),
    _e("HSL_M_start_sa_move", "point to point"),
    _e("HSL_M_p_change", "point to point", order=_M, note="Table 4-7"),
    _e("HSL_M_set_move_ratio", "point to point", order=_M, note="4.6 (axis, 2.5)"),
    _e("HSL_M_motion_done", "point to point", order=_M),
    _e("HSL_M_move_t_distance", "simplified", note="Table 6-2"),
    _e("HSL_M_move_t_position", "simplified", _H),
    _e("HSL_M_move_s_distance", "simplified", _H),
    _e("HSL_M_move_s_position", "simplified", _H),
    _e("HSL_M_set_str_velocity", "simplified", _H),
    _e("HSL_M_set_max_velocity", "simplified", _H),
    _e("HSL_M_set_Tacc", "simplified", _H),
    _e("HSL_M_set_Tdec", "simplified", _H),
    _e("HSL_M_set_SVacc", "simplified", _H),
    _e("HSL_M_set_SVdec", "simplified", _H),
    # interpolation
    *(_e(f"HSL_M_start_{p}_move_{pair}", "linear", order=_M if (p, pair) == ("tr", "xy")
         else _H, note="4.6 example" if (p, pair) == ("tr", "xy") else "")
      for pair in ("xy", "zu") for p in ("tr", "ta", "sr", "sa")),
    *(_e(f"HSL_M_start_{p}_line{n}", "linear")
      for n in (2, 3, 4) for p in ("tr", "ta", "sr", "sa")),
    _e("HSL_M_start_a_arc_xy", "circular", order=_M, note="4.6 example (no DIR: CW)"),
    _e("HSL_M_start_r_arc_xy", "circular"),
    _e("HSL_M_start_a_arc_zu", "circular"),
    _e("HSL_M_start_r_arc_zu", "circular"),
    _e("HSL_M_start_a_arc2", "circular"),
    _e("HSL_M_start_r_arc2", "circular"),
    _e("HSL_M_start_tr_arc_xyu", "circular", note="axis 3 must be idle, not moved"),
    _e("HSL_M_start_ta_arc_xyu", "circular", _H),
    # homing
    _e("HSL_M_set_home_config", "homing", note="modes 2-5, 7 low confidence"),
    _e("HSL_M_home_move", "homing"),
    _e("HSL_M_home_search", "homing"),
    _e("HSL_M_set_org_offset", "homing", _H),
    _e("HSL_M_escape_home", "homing", _H),
    # motion I/O
    _e("HSL_M_set_alm", "motion I/O", note="logic as the machine file wires it"),
    _e("HSL_M_set_el", "motion I/O"),
    _e("HSL_M_set_el_logic", "motion I/O", note="logic as the machine file wires it"),
    _e("HSL_M_set_inp", "motion I/O"),
    _e("HSL_M_set_erc", "motion I/O", note="width codes 0..7 (PCL6045)"),
    _e("HSL_M_set_sd", "motion I/O"),
    _e("HSL_M_set_ltc_logic", "motion I/O"),
    _e("HSL_M_set_pls_outmode", "motion I/O", note="must match the machine file"),
    _e("HSL_M_set_pls_iptmode", "motion I/O", note="must match the machine file"),
    _e("HSL_M_set_feedback_src", "motion I/O", note="1 EA/EB, 0 output pulses"),
    _e("HSL_M_Set_Servo", "motion I/O"),
    _e("HSL_M_set_servo", "motion I/O", note="5.3 spelling"),
    _e("HSL_M_get_io_status", "motion I/O", note="bits of manual notes 2.4"),
    # counters
    _e("HSL_M_get_position", "counters"),
    _e("HSL_M_set_position", "counters"),
    _e("HSL_M_get_command", "counters"),
    _e("HSL_M_set_command", "counters"),
    _e("HSL_M_get_error_counter", "counters"),
    _e("HSL_M_reset_error_counter", "counters"),
    _e("HSL_M_get_general_counter", "counters"),
    _e("HSL_M_set_general_counter", "counters", note="(axis, CntSrc, Value)"),
    _e("HSL_M_get_target_pos", "counters"),
    _e("HSL_M_reset_target_pos", "counters"),
    _e("HSL_M_get_latch_data", "counters", note="LatchNo 0..3 = the four counters (ours)"),
    # comparators
    _e("HSL_M_set_softlimit", "comparators"),
    _e("HSL_M_set_soft_limit", "comparators", _H),
    _e("HSL_M_enable_softlimit", "comparators"),
    _e("HSL_M_enable_soft_limit", "comparators", _H),
    _e("HSL_M_diable_softlimit", "comparators", note="the manual's misspelling"),
    _e("HSL_M_disable_softlimit", "comparators", _O, _H),
    _e("HSL_M_disable_soft_limit", "comparators", _H),
    _e("HSL_M_error_counter_check", "comparators", note="Table 4-8 name"),
    _e("HSL_M_set_error_counter_check", "comparators"),
    _e("HSL_M_set_general_comparator", "comparators", note="codes of manual notes 2.5"),
    _e("HSL_M_set_trigger_comparator", "comparators", order=_M, note="axes 0, 1 of a module"),
    _e("HSL_M_set_trigger_type", "comparators"),
    _e("HSL_M_build_compare_function", "comparators", order=_M),
    _e("HSL_M_build_compare_table", "comparators", order=_M),
    _e("HSL_M_build_comp_function", "comparators", order=_M, note="4.12 spelling"),
    _e("HSL_M_build_comp_table", "comparators", order=_M, note="4.12 spelling"),
    _e("HSL_M_set_auto_compare", "comparators", order=_M),
    _e("HSL_M_check_compare_data", "comparators", order=_M, note="4.12 example"),
    _e("HSL_M_check_compare_status", "comparators", _H),
    # compensation
    _e("HSL_M_backlash_comp", "compensation"),
    _e("HSL_M_suppress_vibration", "compensation", note="T1, T2 in us (ours)"),
)

#: Every HSL function name the manual's text uses.
MANUAL_NAMES = tuple(e.name for e in TABLE if e.origin == "manual")
BY_NAME = {e.name: e for e in TABLE}


def markdown() -> str:
    """The function table of docs/porting-hsl.md."""
    rows = ["| function | group | name from | argument order from | status | note |",
            "| --- | --- | --- | --- | --- | --- |"]
    rows += [f"| `{e.name}` | {e.group} | {e.origin} | {e.order} | {e.status} | {e.note} |"
             for e in TABLE]
    return "\n".join(rows)
