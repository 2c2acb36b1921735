"""The survey editor's state: one session, the landmark graph being edited, the parameters, an
undo history, and the pipeline re-run after every change. The viser panel (``viz/panel.py``)
is a view over this; everything here is usable (and tested) without a browser.

Edits are validated by building a new :class:`LandmarkGraph`; an invalid one is refused with a
message and nothing changes. All mutations hold one lock, so two browser tabs cannot interleave
half-applied edits.

Nothing the surveyor made is lost: after every change the graph (and the parameters) are written
to a recovery copy beside the graph (``graph.yaml.recovery``, ``params.yaml.recovery``) until
they are saved; ``unsaved`` says whether there is anything to save.
"""

from workstation.editor.survey import SurveyEditor

__all__ = ["SurveyEditor"]
