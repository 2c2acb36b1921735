"""The one colour table (viz/colours.py): what is drawn over the plans reads on white and on the
dark theme, the panel takes its colours from it, and a colour means one thing (issues #30, #50)."""

import re

import numpy as np

from workstation.viz.colours import KINDS, MAP, RULES


def test_what_is_drawn_over_the_plans_reads_on_white_and_on_the_dark_theme():
    """Issue #30 item 3: ground truth was white, invisible on the plan images. Everything drawn
    over a plan has a WCAG contrast of at least 2.4 against white and the dark theme; the panel
    and Rerun take their colours from the one table (no RGB literals in the panel's scene)."""
    import inspect

    from workstation.viz import panel_form, panel_georef, panel_scene
    from workstation.viz.colours import MAP, OVER_PLANS

    def lum(c):
        ch = [(v / 255) / 12.92 if v / 255 <= 0.03928 else ((v / 255 + 0.055) / 1.055) ** 2.4
              for v in c[:3]]  # fmt: skip
        return 0.2126 * ch[0] + 0.7152 * ch[1] + 0.0722 * ch[2]

    def contrast(a, b):
        hi, lo = sorted((lum(a), lum(b)), reverse=True)
        return (hi + 0.05) / (lo + 0.05)

    for name in OVER_PLANS:
        col = MAP[name][0]
        assert contrast(col, (255, 255, 255)) >= 2.4, name
        assert contrast(col, (18, 18, 18)) >= 2.4, name
    for mod in (panel_scene, panel_form, panel_georef):
        found = re.findall(r"[([](\d{1,3}), (\d{1,3}), (\d{1,3})[)\]]", inspect.getsource(mod))
        literals = [t for t in found if max(map(int, t)) >= 10]  # (shapes like (0, 2, 3) aside)
        assert not literals, (mod.__name__, literals)


def test_orange_means_plain_pdr_only():
    """Issue #50 item 6: in Rerun orange was both plain PDR and the barometer rule. Every
    landmark colour (by rule and by detected kind) is now far (CIELAB ΔE ≥ 30) from plain PDR's."""

    def lab(c):
        def lin(v):
            v /= 255
            return v / 12.92 if v <= 0.04045 else ((v + 0.055) / 1.055) ** 2.4

        r, g, b = map(lin, c[:3])
        xyz = (np.array([[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722],
                         [0.0193, 0.1192, 0.9505]]) @ [r, g, b]) / [0.95047, 1.0, 1.08883]  # fmt: skip
        fx, fy, fz = np.where(xyz > 0.008856, np.cbrt(xyz), 7.787 * xyz + 16 / 116)
        return np.array([116 * fy - 16, 500 * (fx - fy), 200 * (fy - fz)])

    raw = lab(MAP["raw_pdr"][0])
    for name, col in {**{f"rule {k!r}": v for k, v in RULES.items()}, **KINDS}.items():
        assert np.linalg.norm(lab(col) - raw) >= 30, name
