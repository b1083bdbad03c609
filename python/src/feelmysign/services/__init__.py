"""What runs beside a command while it works, with no command line of its own.

``watchdog``: restarts the broker or the sleeve of ``feelmysign up`` when one
dies; ``drawing_log``: one line per drawing in ``up``'s terminal, from the
sleeve's events; ``stop_signals``: Ctrl-C, SIGTERM and SIGHUP stop a command
that may have motors on.

The fourth service, the early all-off, is ``feelmysign.early_off``, outside
this package on purpose: a restarted sleeve imports it before its motors are
off, and a package around it would be one more module to load first.
"""
