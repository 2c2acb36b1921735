"""The panel's parameter widgets: one per parameter, its kind (choice, switch, text, slider
over the range a surveyor would try, number) from the parameter's declaration; what the
surveyor sets goes to ``on_change(key, value)``; the "Parameters" folder of every group a re-run
reads, and its widgets set again from loaded parameters."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

from workstation.params import GROUPS, Params
from workstation.params.ui import UI_RANGES


def param_widget(gui, sec: str, f: dataclasses.Field, value, on_change: Callable[[str, Any], None]):
    """The widget of parameter ``f`` of group ``sec``, showing ``value``."""
    m = f.metadata
    key = f"{sec}.{f.name}"
    label = f"{f.name}" + (f" ({m['unit']})" if m.get("unit") else "")
    hint = m.get("help") or None
    if m.get("choices"):
        h = gui.add_dropdown(label, list(m["choices"]), initial_value=value, hint=hint)
    elif isinstance(f.default, bool):
        h = gui.add_checkbox(label, value, hint=hint)
    elif f.default is None or isinstance(f.default, str):
        h = gui.add_text(label, value or "", hint=hint)
    elif m.get("lo") is not None and m.get("hi") is not None:
        is_int = isinstance(f.default, int)
        lo, hi = UI_RANGES.get(key, (m["lo"], m["hi"]))
        lo, hi = (
            min(lo, value),
            max(hi, value),
        )  # a loaded value outside the usual range stays reachable
        step = 1 if is_int else _nice_step(lo, hi)
        h = gui.add_slider(label, min=lo, max=hi, step=step, initial_value=value, hint=hint)
    else:
        h = gui.add_number(label, value, hint=hint)

    @h.on_update
    def _(_e) -> None:
        v = h.value
        if isinstance(v, str) and (f.default is None):
            v = v.strip() or None
        on_change(key, v)

    return h


def _nice_step(lo: float, hi: float) -> float:
    span = hi - lo
    for s in (0.001, 0.005, 0.01, 0.05, 0.1, 0.5, 1.0, 5.0, 10.0):
        if span / s <= 2000:
            return s
    return 10.0


def params_folder(gui, params: Params, on_change: Callable[[str, Any], None]) -> dict[str, Any]:
    """The "Parameters" folder: every group a re-run reads (not ``localize``, read by localize
    and evaluate), one widget a parameter; the widgets by "section.name"."""
    handles: dict[str, Any] = {}
    with gui.add_folder("Parameters", expand_by_default=False):
        # the group that decides the reference points opens (panel_text.DECIDES)
        opens = "belief" if params.radiomap.acceptance == "belief" else "radiomap"
        for sec, kind in GROUPS.items():
            if sec == "localize":
                continue
            with gui.add_folder(sec, expand_by_default=sec == opens):
                values = getattr(params, sec)
                for f in dataclasses.fields(kind):
                    handles[f"{sec}.{f.name}"] = param_widget(
                        gui, sec, f, getattr(values, f.name), on_change
                    )
    return handles


def show_params(handles: dict[str, Any], params: Params) -> None:
    """Each widget set to ``params``' value where it differs (a text widget shows None as "")."""
    d = params.to_dict()
    for key, h in handles.items():
        sec, name = key.split(".")
        v = d[sec][name]
        if isinstance(h.value, str) and v is None:
            v = ""
        if h.value != v:
            h.value = v
