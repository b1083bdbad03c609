"""The sleeve's rules without I/O: no clock, no thread, no MQTT (numbers in, verdicts out).

The daemon and the player are the shell around them; the simulations (research
playback, the study's offline sleeve, the bench) and the page (``web/src``, from
the vectors in ``testdata/queue/``) run the same rules. One module is the exception,
``controls``: the wearer's controls keep their state in a file, as they must survive a
restart.
"""
