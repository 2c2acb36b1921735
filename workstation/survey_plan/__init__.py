"""The survey walk planned before anyone walks (``workstation plan``): a route over every edge
of the landmark graph (:mod:`.postman`), its legs, stops and pace (:mod:`.plan`, :mod:`.pace`),
written and read back (:mod:`.output`), and a recorded walk checked against it
(:mod:`.check`)."""
