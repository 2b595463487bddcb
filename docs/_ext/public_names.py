"""Cross-references to our own names resolve to the public name a script uses.

The API reference documents every public name once, as ``plateimpact.X``
(``api/index.rst``). Docstrings and annotations name the same objects by their short
name (``Plate``) or by the module that defines them (``plateimpact.model.bodies.Plate``);
both resolve here to ``plateimpact.Plate`` (and ``Plate.thickness`` to
``plateimpact.Plate.thickness``). A reference to anything else of ours still fails the
nitpicky build. The build also fails if a public name has no entry in the API reference.
"""

from __future__ import annotations

import inspect
import re
import sys
from pathlib import Path
from typing import Any

import attrs

import plateimpact
from plateimpact import _EXPORTS, _SUBMODULES

API_INDEX = Path(__file__).resolve().parents[1] / "api" / "index.rst"


def public_target(target: str) -> str | None:
    """The public ``plateimpact.X...`` path of ``target``, or None if it names none."""
    target = target.lstrip("~.")
    parts = target.split(".")
    if parts[0] == "plateimpact":
        # plateimpact.model.bodies.Plate.mass -> the first exported name along the path
        for i, part in enumerate(parts[1:], start=1):
            if part in _EXPORTS and _EXPORTS[part] == ".".join(parts[1:i]):
                return ".".join(["plateimpact", *parts[i:]])
        for alias, module in _SUBMODULES.items():  # plateimpact.units is itself
            if ".".join(parts[1:]).startswith(alias + ".") or parts[1:] == [alias]:
                return ".".join(["plateimpact", module, *parts[2:]])
        return None
    if parts[0] in _EXPORTS:
        return ".".join(["plateimpact", *parts])
    return None


def documented_in_page_module(env: Any, docname: str, target: str) -> str | None:
    """``target`` as the module of the page's public name sees it: a short name in the
    docstring of ``plateimpact.Plate`` means the one in ``plateimpact.model.bodies``, as
    Python resolves it there, wherever that one is documented (the module's page, or the
    package that re-exports it). None unless exactly one documented object fits."""
    objects = env.get_domain("py").objects
    short = target.lstrip("~.")
    fits = [o for o in objects if o.startswith("plateimpact.") and o.endswith("." + short)]
    name = docname.rsplit("/", 1)[-1].split(".")
    if name[:1] != ["plateimpact"] or len(name) < 2:  # a summary table: only a unique fit
        return fits[0] if len(fits) == 1 else None
    module = f"plateimpact.{_EXPORTS[name[1]]}" if name[1] in _EXPORTS else ".".join(name)
    defined_here = [o for o in fits if o == f"{module}.{short}"]
    if defined_here:
        return defined_here[0]
    package = module.rsplit(".", 1)[0]
    nearby = [o for o in fits if o.startswith(package + ".")]
    return nearby[0] if len(nearby) == 1 else fits[0] if len(fits) == 1 else None


def resolve(app: Any, env: Any, node: Any, contnode: Any) -> Any:
    if node.get("refdomain") != "py":
        return None
    original = node["reftarget"]
    target = public_target(original)
    if target is None or target == original:
        target = documented_in_page_module(env, node["refdoc"], original)
    if target is None or target == original:
        return None
    domain = env.get_domain("py")
    found = domain.resolve_xref(
        env, node["refdoc"], app.builder, node["reftype"], target, node, contnode
    )
    if found is None:
        matches = domain.resolve_any_xref(env, node["refdoc"], app.builder, target, node, contnode)
        found = matches[0][1] if matches else None
    return found


def doc_comment_of_public_data(
    app: Any, what: str, name: str, obj: Any, options: Any, lines: list[str]
) -> None:
    """A public constant (``plateimpact.RTOL``, ``plateimpact.EVENTS``) shows the ``#:``
    comment above its definition, in the module that defines it, not the docstring of
    its value's class (an ``Event``, a ``Parameter``, pluggy's marker)."""
    if what not in ("data", "attribute") or not name.startswith("plateimpact."):
        return
    short = name.removeprefix("plateimpact.")
    if short not in _EXPORTS:
        return
    from sphinx.pycode import ModuleAnalyzer

    docs = ModuleAnalyzer.for_module(f"plateimpact.{_EXPORTS[short]}").find_attr_docs()
    lines[:] = list(docs.get(("", short), []))
    if not lines:
        lines[:] = [f"Defined in ``plateimpact.{_EXPORTS[short]}``."]


def check_every_public_name_listed(app: Any) -> None:
    text = API_INDEX.read_text()
    listed = set(re.findall(r"^   (\S+)$", text, flags=re.M))
    listed |= set(re.findall(r"^\.\. auto\w+:: (\S+)$", text, flags=re.M))
    modules = set(_SUBMODULES.values())
    missing = sorted(set(_EXPORTS) - listed) + sorted(modules - listed)
    if missing:
        from sphinx.util import logging

        logging.getLogger(__name__).warning(
            "public names with no entry in docs/api/index.rst: %s", ", ".join(missing)
        )


def no_signature_for_data(
    app: Any, what: str, name: str, obj: Any, options: Any, signature: Any, annotation: Any
) -> tuple[()] | None:
    """Data has no signature. A type alias (``StepperState = dict[str, ...]``) is
    callable, so numpydoc would answer one, which Sphinx 9.0 then fails to store (an
    IndexError: it found none itself). An empty, non-None answer stops the event there
    and keeps autodoc's own (none)."""
    return () if what == "data" else None


def attrs_init_defaults(app: Any, obj: Any, bound_method: bool) -> None:
    """The defaults of an attrs class's ``__init__`` as values. With
    ``autodoc_preserve_defaults`` autodoc shows defaults as the source writes them
    (``obliquities=MAP_OBLIQUITIES``, not the array), but the source of the ``__init__``
    attrs generates says ``attr_dict['unit'].default``. There a default shows as its repr,
    or as the module-level name it is (``NO_DEFAULT``); a factory as ``<factory>``."""
    code = getattr(obj, "__code__", None)
    if code is None or not code.co_filename.startswith("<attrs generated"):
        return
    from sphinx.ext.autodoc.preserve_defaults import DefaultValue

    vars(obj).pop("__signature__", None)  # preserve_defaults' version
    module = vars(sys.modules[obj.__module__])
    parameters = []
    for parameter in inspect.signature(obj).parameters.values():
        default = parameter.default
        if default is not parameter.empty:
            named = [k for k, v in module.items() if v is default and k.isupper()]
            text = "<factory>" if default is attrs.NOTHING else (named or [repr(default)])[0]
            parameter = parameter.replace(default=DefaultValue(text))
        parameters.append(parameter)
    obj.__signature__ = inspect.signature(obj).replace(parameters=parameters)


def setup(app: Any) -> dict[str, Any]:
    app.connect("missing-reference", resolve)
    app.connect("builder-inited", check_every_public_name_listed)
    app.connect("autodoc-process-docstring", doc_comment_of_public_data)
    app.connect("autodoc-process-signature", no_signature_for_data, priority=400)
    app.connect("autodoc-before-process-signature", attrs_init_defaults)
    app.config.autosummary_context = {"exported": sorted(_EXPORTS)}
    return {"version": plateimpact.__version__, "parallel_read_safe": True}
