"""The CLI's rich consoles (a light module: the error path of `main` imports it)."""

from __future__ import annotations


def new_console(stderr: bool = False):
    """A rich Console that prints user text as given: no emoji codes (a range '1:100:0.001'
    printed as '1💯0.001', a name 'foo:smile:' as 'foo😄'); markup is escaped by callers."""
    from rich.console import Console

    return Console(stderr=stderr, emoji=False)
