"""Everything the subcommands read from their command line, in one place.

``parser``: the ``CliParser`` every command is built with (one ``Error:`` line,
exit 2, for a usage error); ``values``: the option types (ranges, files, sizes)
that turn a word into a checked value; ``layout``, ``broker``, ``lan``,
``emulation``: option groups several subcommands share; ``strokes``: the
strokes ``plan`` takes as arguments or on stdin. Nothing here runs a sleeve, a
broker or a listener (that is ``feelmysign.services``), and nothing here is
imported before the early all-off (``feelmysign.early_off``).
"""
