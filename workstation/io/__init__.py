"""Every file format we read and write that is not a sensor log (those are in
:mod:`workstation.session`): atomic writes and backups (:mod:`.atomic`), YAML read with
``safe_load`` and errors naming file and line (:mod:`.yamlio`), Arrow columns without pandas
(:mod:`.arrow`), radio maps (:mod:`.map_read`), landmark graphs (:mod:`.graph_read`), a
surveyor's fix of a campaign walk (:mod:`.walk_fixes`). Writers of a run's results:
:mod:`workstation.export`."""
