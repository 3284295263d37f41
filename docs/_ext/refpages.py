"""Reference pages generated at build time, so that nothing public goes undocumented.

- ``api/``: one page per name of ``imunoise.__all__`` (autodoc of the function, class,
  exception or module; the version string as data) and an index grouped by kind;
- ``cli/``: one page per subcommand of the ``imunoise`` argparse parser (usage,
  description, every option with its help), and an index of them.

Both lists are read from the package when the docs build: a name added to ``__all__`` or
a subcommand added to the parser gets its page without an edit here. The generator needs
no Sphinx (``tests/docs`` calls :func:`write_pages` directly); :func:`setup` hooks it into
the build.
"""

from __future__ import annotations

import argparse
import inspect
import re
from pathlib import Path

#: Folders (under the docs source) the pages are written to; gitignored.
API_DIR = "api"
CLI_DIR = "cli"

#: Order and headings of the API index.
KINDS = {
    "function": "Functions",
    "class": "Result and data classes",
    "exception": "Exceptions",
    "module": "Modules",
    "data": "Data",
}


def api_kind(obj) -> str:
    """``function``, ``class``, ``exception``, ``module`` or ``data``."""
    if inspect.ismodule(obj):
        return "module"
    if inspect.isclass(obj):
        return "exception" if issubclass(obj, BaseException) else "class"
    if callable(obj):
        return "function"
    return "data"


def page_name(name: str) -> str:
    """The file stem of a name's page (``__version__`` -> ``version``)."""
    return name.strip("_") or name


def summary(obj) -> str:
    """The first sentence of a docstring, on one line."""
    doc = inspect.getdoc(obj) or ""
    first = doc.split("\n\n")[0].replace("\n", " ").strip()
    return first


def _title(text: str) -> str:
    return f"{text}\n{'=' * len(text)}\n"


def api_page(name: str, obj) -> str:
    """The reST of one public name's page."""
    kind = api_kind(obj)
    qualified = f"imunoise.{name}"
    if kind == "module":
        return (f"{_title(qualified)}\n.. automodule:: {qualified}\n   :members:\n"
                "   :show-inheritance:\n")
    if kind == "data":
        return (f"{_title(qualified)}\n.. py:data:: {qualified}\n   :value: {obj!r}\n\n"
                f"   The installed version of imunoise (semantic versioning; the same as\n"
                "   ``imunoise --version`` and the wheel's metadata).\n")
    directive = {"function": "autofunction", "class": "autoclass",
                 "exception": "autoexception"}[kind]
    options = "   :members:\n" if kind in ("class", "exception") else ""
    return f"{_title(qualified)}\n.. currentmodule:: imunoise\n\n.. {directive}:: {name}\n{options}"


def api_index(objects: dict[str, object]) -> str:
    """The API index: every public name under its kind, with its first sentence."""
    out = [_title("API reference"),
           "Every public name of ``imunoise`` (``imunoise.__all__``), each on its own page, "
           "from its docstring. Modules (``imunoise.export``, ``imunoise.plot`` …) hold "
           "the functions that are not at the top level.\n"]
    for kind, heading in KINDS.items():
        names = [n for n, o in objects.items() if api_kind(o) == kind]
        if not names:
            continue
        out.append(f"{heading}\n{'-' * len(heading)}\n")
        out.append(".. list-table::\n   :widths: 30 70\n")
        for n in names:
            # the first paragraph of a docstring is reST already (roles kept)
            text = summary(objects[n]) if kind != "data" else "The version string."
            out.append(f"   * - :doc:`imunoise.{n} <{page_name(n)}>`\n     - {text}")
        out.append("")
        out.append(".. toctree::\n   :hidden:\n")
        out.extend(f"   {page_name(n)}" for n in names)
        out.append("")
    return "\n".join(out) + "\n"


# -- command line ----------------------------------------------------------------------

def subcommands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    """Every subcommand of ``parser`` (name -> its parser), in the parser's order."""
    found: dict[str, argparse.ArgumentParser] = {}
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                if sub not in found.values():  # aliases share one parser
                    found[name] = sub
    return found


def _subcommand_help(parser: argparse.ArgumentParser) -> dict[str, str]:
    out = {}
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for choice in action._choices_actions:
                out[choice.dest] = choice.help or ""
    return out


_RST_SPECIAL = re.compile(r"([\\`*|_])")


def _escape(text: str) -> str:
    """Plain text safe inside reST (no roles, emphasis, substitutions or targets)."""
    return _RST_SPECIAL.sub(r"\\\1", text)


def _option_signature(parser: argparse.ArgumentParser, action: argparse.Action) -> str:
    formatter = parser._get_formatter()
    if not action.option_strings:
        return formatter._metavar_formatter(action, action.dest)(1)[0]
    if action.nargs == 0:
        return ", ".join(action.option_strings)
    metavar = formatter._format_args(action, action.dest.upper())
    return ", ".join(f"{opt} {metavar}" for opt in action.option_strings)


def _option_help(parser: argparse.ArgumentParser, action: argparse.Action) -> str:
    if not action.help:
        return ""
    return " ".join(parser._get_formatter()._expand_help(action).split())


def cli_page(prog: str, parser: argparse.ArgumentParser, help_text: str) -> str:
    """The reST of one command's page: usage, description, options by group."""
    out = [_title(prog)]
    if help_text:
        out.append(_escape(help_text[:1].upper() + help_text[1:]) + ".\n")
    usage = parser.format_usage().removeprefix("usage: ").strip()
    out.append(".. code-block:: text\n\n   " + "\n   ".join(usage.splitlines()) + "\n")
    if parser.description:
        out.append(_escape(" ".join(parser.description.split())) + "\n")
    out.append(f".. program:: {prog}\n")
    for group in parser._action_groups:
        actions = [a for a in group._group_actions if a.help is not argparse.SUPPRESS
                   and not isinstance(a, argparse._SubParsersAction)]
        if not actions:
            continue
        title = (group.title or "options")
        out.append(f"{title[:1].upper() + title[1:]}\n{'-' * len(title)}\n")
        if group.description:
            out.append(_escape(" ".join(group.description.split())) + "\n")
        for action in actions:
            out.append(f".. option:: {_option_signature(parser, action)}\n")
            text = _option_help(parser, action)
            if action.choices is not None and action.metavar is not None:
                # the metavar hides the choices the signature would otherwise show
                choices = ", ".join(str(c) for c in action.choices)
                text = f"{text} (one of: {choices})" if text else f"One of: {choices}."
            if text:
                out.append("   " + _escape(text) + "\n")
    if parser.epilog:
        out.append(_escape(" ".join(parser.epilog.split())) + "\n")
    return "\n".join(out)


def cli_index(parser: argparse.ArgumentParser) -> str:
    """The command-line index: the global options and every subcommand."""
    commands = subcommands(parser)
    helps = _subcommand_help(parser)
    out = [_title("Command-line reference"),
           "Generated from the ``imunoise`` argument parser: every subcommand has a page. "
           "Errors are one line on stderr with exit status 2; Ctrl-C exits 130.\n",
           cli_page("imunoise", parser, "").split("\n", 2)[2],
           "Commands\n--------\n",
           ".. list-table::\n   :widths: 20 80\n"]
    for name in commands:
        out.append(f"   * - :doc:`{name}`\n     - {_escape(helps.get(name, ''))}")
    out.append("\n.. toctree::\n   :hidden:\n")
    out.extend(f"   {name}" for name in commands)
    return "\n".join(out) + "\n"


# -- writing ---------------------------------------------------------------------------

def public_objects() -> dict[str, object]:
    """``imunoise.__all__`` name -> object (lazy modules loaded)."""
    import imunoise

    return {name: getattr(imunoise, name) for name in imunoise.__all__}


def cli_parser() -> argparse.ArgumentParser:
    from imunoise import cli

    return cli._build_parser()


def _write_if_changed(path: Path, text: str) -> None:
    # An unchanged page keeps its mtime, so an incremental build does not reread it.
    if not path.exists() or path.read_text(encoding="utf-8") != text:
        path.write_text(text, encoding="utf-8")


def write_pages(source: Path) -> dict[str, list[Path]]:
    """Write the API and CLI pages under the docs ``source`` folder; pages of names that
    no longer exist are removed. Returns the pages written, per folder."""
    written: dict[str, list[Path]] = {}
    objects = public_objects()
    parser = cli_parser()
    helps = _subcommand_help(parser)
    pages = {
        API_DIR: {"index": api_index(objects)}
        | {page_name(n): api_page(n, o) for n, o in objects.items()},
        CLI_DIR: {"index": cli_index(parser)}
        | {name: cli_page(f"imunoise {name}", sub, helps.get(name, ""))
           for name, sub in subcommands(parser).items()},
    }
    for folder, texts in pages.items():
        target = source / folder
        target.mkdir(exist_ok=True)
        for stale in set(target.glob("*.rst")) - {target / f"{s}.rst" for s in texts}:
            stale.unlink()
        written[folder] = []
        for stem, text in texts.items():
            path = target / f"{stem}.rst"
            _write_if_changed(path, text)
            written[folder].append(path)
    return written


def _generate(app) -> None:
    write_pages(Path(app.srcdir))


def setup(app):
    app.connect("builder-inited", _generate)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
