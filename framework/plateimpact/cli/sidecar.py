"""A CSV and the JSON beside it (``FILE.csv.json``: the inputs and provenance of what the
CSV holds), written together (storage.together) and tied by the CSV's SHA-256.

``sweep --csv FILE`` and ``run --trajectory FILE`` write the pair. The JSON's
``csv_sha256`` is the SHA-256 of the CSV's bytes (``sha256sum FILE``); a pair whose
digests differ does not belong together (:func:`pair_matches`).
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Iterable, Mapping
from typing import IO, Any

from ..base.untrusted import load_json_file
from ..storage.output import streamed
from ..storage.together import Output
from .common import UsageError

#: The key of the sidecar that holds the CSV's SHA-256 [hex].
DIGEST_KEY = "csv_sha256"


def sidecar(csv_path: str) -> str:
    """Where the inputs and provenance of ``csv_path`` go: FILE.json for FILE (the CSV
    stays plain for any CSV reader)."""
    return f"{csv_path}.json"


def csv_and_sidecar(
    csv_path: str, flag: str, chunks: Iterable[str], record: Mapping[str, Any]
) -> list[Output]:
    """The CSV of the texts ``chunks`` (streamed, a chunk at a time) and its sidecar,
    ``record`` with the CSV's SHA-256, as a set for storage.together.write_together."""
    digest = hashlib.sha256()

    def write_sidecar(handle: IO[bytes]) -> None:  # after the CSV: its digest is known
        found = {**record, DIGEST_KEY: digest.hexdigest()}
        handle.write((json.dumps(found, indent=2) + "\n").encode())

    return [
        Output(csv_path, flag, streamed(chunks, digest)),
        Output(sidecar(csv_path), flag, write_sidecar, "json"),
    ]


def pair_matches(csv_path: str | os.PathLike[str]) -> bool:
    """Whether the sidecar of ``csv_path`` describes the CSV there (its ``csv_sha256``
    is the CSV's SHA-256)."""
    path = os.fspath(csv_path)
    record = load_json_file(sidecar(path), UsageError)
    digest = hashlib.sha256()
    with open(path, "rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    return isinstance(record, dict) and record.get(DIGEST_KEY) == digest.hexdigest()
