"""Edits as small diff atoms, grouped into gestures, kept in bounded undo/redo stacks.

An atom says where, what was there and what is there now; undo writes the old values back.
A gesture (one click, one brush stroke) is one undo step, however many atoms it holds.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
from typing import TypeAlias

import numpy as np
import numpy.typing as npt

from storage.model import Goal, Instance, LabelClass


@dataclass(frozen=True, eq=False)
class LabelAtom:
    """Faces ``face_ids`` change instance id from ``old_ids`` to ``new_ids`` (-1 = unlabelled)."""

    face_ids: npt.NDArray[np.int32]
    old_ids: npt.NDArray[np.int32]
    new_ids: npt.NDArray[np.int32]

    def inverted(self) -> LabelAtom:
        """Return the atom that undoes this one."""
        return LabelAtom(self.face_ids, self.new_ids, self.old_ids)


@dataclass(frozen=True)
class ClassAtom:
    """A class is added (old None), removed (new None) or recoloured, keyed by name."""

    name: str
    old: LabelClass | None
    new: LabelClass | None

    def inverted(self) -> ClassAtom:
        """Return the atom that undoes this one."""
        return ClassAtom(self.name, self.new, self.old)


@dataclass(frozen=True)
class InstanceAtom:
    """An instance id is created (old None), deleted (new None) or renamed/moved."""

    instance_id: int
    old: Instance | None
    new: Instance | None

    def inverted(self) -> InstanceAtom:
        """Return the atom that undoes this one."""
        return InstanceAtom(self.instance_id, self.new, self.old)


@dataclass(frozen=True, eq=False)
class LayerAtom:
    """A per-vertex layer is added (old None), removed (new None) or replaced."""

    name: str
    old: npt.NDArray[np.float32] | None
    new: npt.NDArray[np.float32] | None

    def inverted(self) -> LayerAtom:
        """Return the atom that undoes this one."""
        return LayerAtom(self.name, self.new, self.old)


@dataclass(frozen=True)
class GoalsAtom:
    """The goal list changes as a whole (goal lists are short; this covers reorder too)."""

    old: tuple[Goal, ...]
    new: tuple[Goal, ...]

    def inverted(self) -> GoalsAtom:
        """Return the atom that undoes this one."""
        return GoalsAtom(self.new, self.old)


Atom: TypeAlias = LabelAtom | ClassAtom | InstanceAtom | LayerAtom | GoalsAtom
Gesture: TypeAlias = tuple[Atom, ...]


class History:
    """Bounded undo/redo stacks of gestures, with an optional open gesture being staged.

    Not thread-safe on its own: ``MapDocument`` calls it under its lock.
    """

    def __init__(self, max_steps: int = 200) -> None:
        self.max_steps = max_steps
        self._undo: deque[Gesture] = deque(maxlen=max_steps)
        self._redo: deque[Gesture] = deque(maxlen=max_steps)
        self._staged: list[Atom] | None = None
        self._depth = 0

    @property
    def is_open(self) -> bool:
        """Return True while a gesture is being recorded."""
        return self._staged is not None

    def begin(self) -> None:
        """Open a gesture (nested begins join the outer one)."""
        self._depth += 1
        if self._staged is None:
            self._staged = []

    def record(self, atom: Atom) -> None:
        """Keep an applied atom: staged when a gesture is open, else as its own step."""
        if self._staged is not None:
            self._staged.append(atom)
        else:
            self._push((atom,))

    def commit(self) -> Gesture:
        """Close the gesture; push it as one undo step when it holds anything."""
        self._depth = max(0, self._depth - 1)
        if self._depth > 0 or self._staged is None:
            return ()
        gesture = tuple(self._staged)
        self._staged = None
        if gesture:
            self._push(gesture)
        return gesture

    def abort(self) -> Gesture:
        """Close the gesture without keeping it; return its atoms so the caller can revert them."""
        gesture = tuple(self._staged or ())
        self._staged = None
        self._depth = 0
        return gesture

    def _push(self, gesture: Gesture) -> None:
        self._undo.append(gesture)
        self._redo.clear()

    def pop_undo(self) -> Gesture | None:
        """Take the newest gesture off the undo stack onto the redo stack."""
        if not self._undo:
            return None
        gesture = self._undo.pop()
        self._redo.append(gesture)
        return gesture

    def pop_redo(self) -> Gesture | None:
        """Take the newest undone gesture back onto the undo stack."""
        if not self._redo:
            return None
        gesture = self._redo.pop()
        self._undo.append(gesture)
        return gesture

    @property
    def can_undo(self) -> bool:
        """Return True when there is a gesture to undo."""
        return bool(self._undo)

    @property
    def can_redo(self) -> bool:
        """Return True when there is a gesture to redo."""
        return bool(self._redo)

    def clear(self) -> None:
        """Forget every step (after loading another map)."""
        self._undo.clear()
        self._redo.clear()
        self._staged = None
        self._depth = 0
