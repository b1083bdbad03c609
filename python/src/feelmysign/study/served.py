"""The study served by ``feelmysign up --study FILE``: its API, sending with the sender's login.

``study_api(path, credentials)`` is a context manager giving the handler the web server
mounts under ``/api/study/`` (None without a study), connected to the broker ``up``
started, and closing that connection on exit.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from feelmysign.broker import Credentials
from feelmysign.study.api import StudyApi
from feelmysign.study.runner import Session
from feelmysign.study.sleeve_link import SleeveLink
from feelmysign.study.store import StudyStore
from feelmysign.webserver import Api


@contextmanager
def study_api(path: Path | None, credentials: Credentials) -> Iterator[Api | None]:
    if path is None:
        yield None
        return
    store = StudyStore(path)
    try:
        with SleeveLink(credentials.settings("sender")) as link:
            results = path.resolve().parent / f"{path.stem}-results"
            yield StudyApi(Session(store, link.play), results).handle
    finally:
        store.close()
