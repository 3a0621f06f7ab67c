"""The command-line reference page, made from the ``grainlab`` parsers themselves.

``grainlab.cli.build_parser()`` is the parser ``grainlab`` runs with, so this page
cannot drift from the program: each command (and each subcommand of a command) gets
its usage line, its description and a table of its arguments, group by group, with
the help text and the default as ``--help`` prints them. docs/cli.md stays the
guide, with examples and every configuration key.
"""

from __future__ import annotations

import argparse

#: Where the page goes in the site.
CLI_URI = "reference/cli.md"


def _subparsers(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            return dict(action.choices)
    return {}


def _cell(text: str) -> str:
    return " ".join(text.split()).replace("|", "\\|")


def _argument_row(parser: argparse.ArgumentParser, action: argparse.Action) -> str:
    formatter = parser._get_formatter()
    if action.option_strings:
        names = ", ".join(f"`{name}`" for name in action.option_strings)
        value = "" if action.nargs == 0 else formatter._format_args(action, action.dest.upper())
    else:
        names, value = f"`{formatter._metavar_formatter(action, action.dest)(1)[0]}`", ""
    help_text = formatter._expand_help(action) if action.help else ""
    default = action.default
    shown = "" if default in (None, False, argparse.SUPPRESS) or action.nargs == 0 else f"`{default}`"
    return f"| {names} | {_cell(value) and f'`{_cell(value)}`'} | {_cell(help_text)} | {shown} |"


def _groups(parser: argparse.ArgumentParser) -> list[str]:
    lines: list[str] = []
    for group in parser._action_groups:
        actions = [a for a in group._group_actions if not isinstance(a, argparse._HelpAction)]
        if not actions:
            continue
        lines += ["", f"*{group.title}*", "", "| argument | value | meaning | default |", "| --- | --- | --- | --- |"]
        lines += [_argument_row(parser, action) for action in actions]
    return lines


def _command(name: str, parser: argparse.ArgumentParser, level: int) -> list[str]:
    lines = ["", f"{'#' * level} `{name}`", "", "```text", parser.format_usage().strip(), "```"]
    if parser.description:
        lines += ["", parser.description]
    lines += _groups(parser)
    for sub, subparser in _subparsers(parser).items():
        lines += _command(f"{name} {sub}", subparser, min(level + 1, 4))
    return lines


def cli_markdown(parser: argparse.ArgumentParser) -> str:
    """The page: the program, then every command in the order ``--help`` lists them."""
    lines = [
        "# Command-line reference",
        "",
        "Made from the parsers of `grainlab` when the site is built: every command and",
        "argument, with its help text and default. For examples and the configuration",
        "keys of `--set`, see [the command-line guide](../cli.md).",
    ]
    lines += _command(parser.prog, parser, 2)
    return "\n".join(lines) + "\n"
