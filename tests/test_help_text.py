"""``--help`` is read in a terminal: the command's and every subcommand's help text is
plain text, without the reStructuredText markup the docstrings it may come from use for
the documentation site (double backquotes, roles such as ``:func:``)."""

from __future__ import annotations

import contextlib
import io
import re

import pytest

from plateimpact.cli import main
from plateimpact.cli.commands import COMMANDS

#: Inline literals, and roles with their target: ``x``, :func:`x`, :class:`~a.B`.
MARKUP = re.compile(r"``|:[a-z]+:`")


def help_text(argv: list[str]) -> str:
    out = io.StringIO()
    with contextlib.redirect_stdout(out), pytest.raises(SystemExit) as stop:
        main(argv)
    assert stop.value.code == 0
    return out.getvalue()


@pytest.mark.parametrize("argv", [["--help"], *([c.name, "--help"] for c in COMMANDS)])
def test_help_is_plain_text(argv):
    text = help_text(argv)
    assert "usage: plateimpact" in text
    assert not MARKUP.search(text), MARKUP.search(text)
