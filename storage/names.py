"""The naming rule mesh_tools imposes on labels, checked where the user types a name.

The RViz map display names a label ``<class>_<instance>`` and rejects any that does not split
into exactly two parts at ``_``; HDF5 paths forbid ``/``. So neither part may hold either.
"""

from __future__ import annotations

from storage.errors import LabelNameError

_FORBIDDEN = {"_": "underscore", "/": "slash"}


def name_problem(name: str, what: str = "name") -> str | None:
    """Return why ``name`` cannot be a class or instance name, or None when it is fine."""
    if not name or not name.strip():
        return f"the {what} is empty"
    if name != name.strip():
        return f"the {what} starts or ends with a space"
    for char, word in _FORBIDDEN.items():
        if char in name:
            return (
                f"the {what} {name!r} contains '{char}' ({word}): mesh_tools writes labels as "
                "<class>_<instance> and HDF5 paths split at '/', so neither part may contain "
                "'_' or '/'"
            )
    if name in (".", ".."):
        return f"the {what} {name!r} is not a valid HDF5 name"
    if len(name) > 128:
        return f"the {what} is longer than 128 characters"
    return None


def check_name(name: str, what: str = "name") -> str:
    """Return ``name`` unchanged, or raise ``LabelNameError`` saying why it is refused."""
    problem = name_problem(name, what)
    if problem is not None:
        raise LabelNameError(problem)
    return name
