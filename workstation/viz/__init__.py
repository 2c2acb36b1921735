"""Rerun and viser, observers at the edge: the Rerun logger (:mod:`.rerun_log`) and its
blueprints (:mod:`.layouts`), the survey panel (:mod:`.panel`, its parts in ``panel_*.py``,
typed over :mod:`.panel_host`), one place for every colour (:mod:`.colours`), the origin check
that keeps other sites' pages from driving the servers (:mod:`.origin_guard`)."""
