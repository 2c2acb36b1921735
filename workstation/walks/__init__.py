"""What needs many walks of one building, above the one-walk pipeline: walks that stood at one
place decide their start together (:mod:`.shared_start`), a walk recorded right after another
starts within reach of where that one ended (:mod:`.chain`), the start a building's map
suggests (:mod:`.start_by_map`), the walks correcting each other (:mod:`.joint`), the graph a
surveyor would draw from tapped walks (:mod:`.graph_from_walks`). Each takes what it needs as
arguments; nothing here is reached from :mod:`workstation.pipeline`."""
