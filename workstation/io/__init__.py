"""Every file format we read and write that is not a sensor log (those are in :mod:`workstation.session`): atomic writes, YAML, radio maps, graphs, a surveyor's walk fixes."""
