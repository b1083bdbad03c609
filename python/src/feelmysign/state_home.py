"""Where feelmysign keeps its state on this machine: ``$XDG_STATE_HOME/feelmysign``
(``~/.local/state/feelmysign`` by default; ``/var/lib/feelmysign`` under the systemd units,
which set ``XDG_STATE_HOME``). One folder per kind below it: ``broker``, ``controls``,
``calibration``, ``pace``, ``trusted``, ``wearer-page``, ``wiring``.

(``feelmysign.early_off`` writes its memo there without this module: the path from a
restart to every motor off imports nothing it can do without.)
"""

from __future__ import annotations

import os


def state_path(*parts: str) -> str:
    """``$XDG_STATE_HOME/feelmysign/<parts...>``."""
    home = os.environ.get("XDG_STATE_HOME") or os.path.expanduser("~/.local/state")
    return os.path.join(home, "feelmysign", *parts)
