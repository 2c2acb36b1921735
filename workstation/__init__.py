"""workstation — turn one smartphone walk into a trustworthy WiFi radio map.

Public API (the rest lives in private implementation modules):

- :func:`workstation.session.load_session` / :class:`workstation.session.Session`
- :class:`workstation.graph.LandmarkGraph`
"""

__version__ = "0.1.0"
