"""``MapDocument``: the one source of truth for an open map, its lock, history and events.

Every change goes through ``apply`` under the document's ``RLock`` (viser runs callbacks on a
thread pool, and several browsers may edit at once). Listeners are called under the lock with
the atom that changed, so they must stay cheap: mark something dirty, return.
"""

from __future__ import annotations

import contextlib
import copy
import logging
import threading
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from types import MappingProxyType
from typing import Any

import numpy as np
import numpy.typing as npt

from geometry import local_origin
from storage.errors import DocumentError
from storage.events import DocumentChanged, DocumentSaved
from storage.history import (
    Atom,
    ClassAtom,
    GoalsAtom,
    History,
    InstanceAtom,
    LabelAtom,
    LayerAtom,
)
from storage.model import UNLABELLED, Goal, Instance, LabelClass, MapData, Texture
from storage.names import check_name

logger = logging.getLogger(__name__)

Listener = Callable[[DocumentChanged | DocumentSaved], None]


def _readonly(a: np.ndarray) -> np.ndarray:
    view = a.view()
    view.flags.writeable = False
    return view


class MapDocument:
    """An open mesh map: geometry, layers, labels, goals, with undo and change events.

    Geometry (vertices, faces, texture, colours) is fixed for the life of a document; opening
    another file makes a new document. Everything else changes through atoms.
    """

    def __init__(self, data: MapData, path: str | Path | None = None) -> None:
        self.lock = threading.RLock()
        self.path: Path | None = Path(path) if path is not None else None
        self._data = data
        self._vertices = _readonly(data.vertices)
        self._faces = _readonly(data.faces)
        assert data.face_labels is not None
        self._face_labels = data.face_labels.copy()
        stored = data.meta.get("origin")
        self.origin: npt.NDArray[np.float64] = (
            np.asarray(stored, dtype=np.float64)
            if stored is not None and np.any(stored)
            else local_origin(data.vertices)
        )
        self._vertices_local: npt.NDArray[np.float32] | None = None
        self.history = History()
        self._listeners: list[Listener] = []
        self.dirty = False

    # ----------------------------------------------------------------- read access
    @property
    def vertices(self) -> npt.NDArray[np.float64]:
        """float64 [N, 3] world coordinates (read-only)."""
        return self._vertices

    @property
    def faces(self) -> npt.NDArray[np.int32]:
        """int32 [F, 3] vertex ids (read-only); row i is face id i."""
        return self._faces

    @property
    def vertices_local(self) -> npt.NDArray[np.float32]:
        """float32 [N, 3] vertices minus ``origin``: what is rendered and picked."""
        if self._vertices_local is None:
            local = (self._vertices - self.origin).astype(np.float32)
            self._vertices_local = _readonly(local)
        return self._vertices_local

    @property
    def n_vertices(self) -> int:
        """Return the vertex count."""
        return len(self._vertices)

    @property
    def n_faces(self) -> int:
        """Return the face count."""
        return len(self._faces)

    @property
    def layers(self) -> Mapping[str, npt.NDArray[np.float32]]:
        """Per-vertex layers by name (read-only mapping of read-only arrays)."""
        return MappingProxyType({k: _readonly(v) for k, v in self._data.layers.items()})

    @property
    def vertex_colors(self) -> npt.NDArray[np.uint8] | None:
        """uint8 [N, 3] vertex colours or None."""
        return self._data.vertex_colors

    @property
    def texture(self) -> Texture | None:
        """The texture (UVs and encoded image) or None."""
        return self._data.texture

    @property
    def face_labels(self) -> npt.NDArray[np.int32]:
        """int32 [F] instance id per face, -1 = unlabelled (read-only view)."""
        return _readonly(self._face_labels)

    @property
    def classes(self) -> Mapping[str, LabelClass]:
        """Label classes by name, in display order."""
        return MappingProxyType(dict(self._data.classes))

    @property
    def instances(self) -> Mapping[int, Instance]:
        """Label instances by id."""
        return MappingProxyType(dict(self._data.instances))

    @property
    def goals(self) -> tuple[Goal, ...]:
        """Goal poses in list order."""
        return tuple(self._data.goals)

    @property
    def meta(self) -> Mapping[str, Any]:
        """Facts about the source file (layout, format, origin...)."""
        return MappingProxyType(self._data.meta)

    @property
    def warnings(self) -> list[str]:
        """What was repaired or skipped when the file was read."""
        return list(self._data.warnings)

    def find_instance(self, class_name: str, name: str) -> int | None:
        """Return the id of instance ``class_name``/``name``, or None."""
        for iid, inst in self._data.instances.items():
            if inst.class_name == class_name and inst.name == name:
                return iid
        return None

    def instance_face_counts(self) -> dict[int, int]:
        """Return the number of faces per instance id (only ids that exist)."""
        with self.lock:
            labelled = self._face_labels[self._face_labels >= 0]
            counts = np.bincount(labelled) if len(labelled) else np.zeros(0, np.int64)
            return {
                iid: int(counts[iid]) if iid < len(counts) else 0 for iid in self._data.instances
            }

    # ----------------------------------------------------------------- events
    def subscribe(self, listener: Listener) -> Callable[[], None]:
        """Call ``listener(event)`` after every change; return a function that unsubscribes."""
        with self.lock:
            self._listeners.append(listener)

        def unsubscribe() -> None:
            with self.lock:
                if listener in self._listeners:
                    self._listeners.remove(listener)

        return unsubscribe

    def _emit(self, event: DocumentChanged | DocumentSaved) -> None:
        for listener in list(self._listeners):
            try:
                listener(event)
            except Exception:  # a broken view must not corrupt the document
                logger.exception("document listener failed")

    # ----------------------------------------------------------------- writing
    @contextlib.contextmanager
    def gesture(self) -> Iterator[None]:
        """Group every atom applied inside into one undo step; revert them on an exception."""
        with self.lock:
            self.history.begin()
            try:
                yield
            except BaseException:
                for atom in reversed(self.history.abort()):
                    self._write(atom.inverted(), replay=True)
                raise
            else:
                self.history.commit()

    def begin_gesture(self) -> None:
        """Open a gesture that spans several callbacks (a brush drag); close with commit/abort."""
        with self.lock:
            self.history.begin()

    def commit_gesture(self) -> None:
        """Close the gesture opened by ``begin_gesture`` as one undo step."""
        with self.lock:
            self.history.commit()

    def abort_gesture(self) -> None:
        """Close the open gesture and revert what it did."""
        with self.lock:
            for atom in reversed(self.history.abort()):
                self._write(atom.inverted(), replay=True)

    def apply(self, atom: Atom) -> None:
        """Write ``atom``, record it for undo and tell the listeners."""
        with self.lock:
            self._write(atom, replay=False)
            self.history.record(atom)

    def _write(self, atom: Atom, *, replay: bool) -> None:
        d = self._data
        if isinstance(atom, LabelAtom):
            self._face_labels[atom.face_ids] = atom.new_ids
        elif isinstance(atom, ClassAtom):
            if atom.new is None:
                d.classes.pop(atom.name, None)
            else:
                d.classes[atom.name] = atom.new
        elif isinstance(atom, InstanceAtom):
            if atom.new is None:
                d.instances.pop(atom.instance_id, None)
            else:
                d.instances[atom.instance_id] = atom.new
        elif isinstance(atom, LayerAtom):
            if atom.new is None:
                d.layers.pop(atom.name, None)
            else:
                d.layers[atom.name] = atom.new
        elif isinstance(atom, GoalsAtom):
            d.goals = list(atom.new)
        else:  # pragma: no cover - the Atom union is closed
            raise TypeError(f"unknown atom {atom!r}")
        self.dirty = True
        self._emit(DocumentChanged(atom, replay=replay))

    def undo(self) -> bool:
        """Undo the newest gesture; return False when there is none."""
        with self.lock:
            if self.history.is_open:
                self.history.commit()
            gesture = self.history.pop_undo()
            if gesture is None:
                return False
            for atom in reversed(gesture):
                self._write(atom.inverted(), replay=True)
            return True

    def redo(self) -> bool:
        """Redo the newest undone gesture; return False when there is none."""
        with self.lock:
            gesture = self.history.pop_redo()
            if gesture is None:
                return False
            for atom in gesture:
                self._write(atom, replay=True)
            return True

    # ----------------------------------------------------------------- labels
    def label_faces(self, face_ids: npt.ArrayLike, instance_id: int) -> LabelAtom | None:
        """Label ``face_ids`` with ``instance_id`` (-1 erases); return the atom (None: no-op)."""
        ids = _sorted_unique(np.asarray(face_ids, dtype=np.int64).ravel())
        with self.lock:
            if instance_id != UNLABELLED and instance_id not in self._data.instances:
                raise DocumentError(f"there is no label instance with id {instance_id}")
            if len(ids) and (ids[0] < 0 or ids[-1] >= self.n_faces):
                raise DocumentError(f"face ids must lie in 0..{self.n_faces - 1}")
            ids = ids.astype(np.int32)
            old = self._face_labels[ids]
            changed = old != instance_id
            if not changed.any():
                return None
            ids, old = ids[changed], old[changed]
            atom = LabelAtom(ids, old, np.full(len(ids), instance_id, dtype=np.int32))
            self.apply(atom)
            return atom

    def add_class(self, name: str, color: tuple[int, int, int]) -> LabelClass:
        """Create a class (validating its name); raise ``DocumentError`` if it exists."""
        check_name(name, "class name")
        with self.lock:
            if name in self._data.classes:
                raise DocumentError(f"a class named {name!r} exists already")
            cls = LabelClass(name, _rgb(color))
            self.apply(ClassAtom(name, None, cls))
            return cls

    def recolor_class(self, name: str, color: tuple[int, int, int]) -> None:
        """Change a class's display colour."""
        with self.lock:
            old = self._class(name)
            new = LabelClass(name, _rgb(color))
            if new != old:
                self.apply(ClassAtom(name, old, new))

    def rename_class(self, name: str, new_name: str) -> None:
        """Rename a class and move its instances along, as one undo step."""
        check_name(new_name, "class name")
        with self.lock, self.gesture():
            old = self._class(name)
            if new_name == name:
                return
            if new_name in self._data.classes:
                raise DocumentError(f"a class named {new_name!r} exists already")
            self.apply(ClassAtom(name, old, None))
            self.apply(ClassAtom(new_name, None, LabelClass(new_name, old.color)))
            for iid, inst in list(self._data.instances.items()):
                if inst.class_name == name:
                    self.apply(InstanceAtom(iid, inst, Instance(new_name, inst.name)))

    def delete_class(self, name: str) -> None:
        """Delete a class, its instances and its labels (faces become unlabelled), undoably."""
        with self.lock, self.gesture():
            old = self._class(name)
            for iid, inst in list(self._data.instances.items()):
                if inst.class_name == name:
                    self._delete_instance(iid, inst)
            self.apply(ClassAtom(name, old, None))

    def add_instance(self, class_name: str, name: str) -> int:
        """Create instance ``name`` of ``class_name`` (validated) and return its id."""
        check_name(name, "instance name")
        with self.lock:
            self._class(class_name)
            if self.find_instance(class_name, name) is not None:
                raise DocumentError(f"{class_name} already has an instance {name!r}")
            iid = max(self._data.instances, default=-1) + 1
            self.apply(InstanceAtom(iid, None, Instance(class_name, name)))
            return iid

    def rename_instance(self, instance_id: int, name: str) -> None:
        """Rename an instance within its class."""
        check_name(name, "instance name")
        with self.lock:
            inst = self._instance(instance_id)
            if name == inst.name:
                return
            if self.find_instance(inst.class_name, name) is not None:
                raise DocumentError(f"{inst.class_name} already has an instance {name!r}")
            self.apply(InstanceAtom(instance_id, inst, Instance(inst.class_name, name)))

    def delete_instance(self, instance_id: int) -> None:
        """Delete an instance and unlabel its faces, as one undo step."""
        with self.lock, self.gesture():
            self._delete_instance(instance_id, self._instance(instance_id))

    def _delete_instance(self, iid: int, inst: Instance) -> None:
        faces = np.flatnonzero(self._face_labels == iid).astype(np.int32)
        if len(faces):
            self.label_faces(faces, UNLABELLED)
        self.apply(InstanceAtom(iid, inst, None))

    def _class(self, name: str) -> LabelClass:
        try:
            return self._data.classes[name]
        except KeyError:
            raise DocumentError(f"there is no class named {name!r}") from None

    def _instance(self, iid: int) -> Instance:
        try:
            return self._data.instances[iid]
        except KeyError:
            raise DocumentError(f"there is no label instance with id {iid}") from None

    # ----------------------------------------------------------------- layers and goals
    def set_layer(self, name: str, values: npt.ArrayLike | None, *, record: bool = True) -> None:
        """Add, replace (values) or remove (None) a per-vertex float32 layer.

        ``record=False`` is for derived layers (the label cost layer follows the labels): the
        change is written and announced but is not an undo step of its own.
        """
        with self.lock:
            new = None
            if values is not None:
                new = np.ascontiguousarray(values, dtype=np.float32).reshape(-1)
                if len(new) != self.n_vertices:
                    raise DocumentError(
                        f"layer {name!r} has {len(new)} values for {self.n_vertices} vertices"
                    )
            atom = LayerAtom(name, self._data.layers.get(name), new)
            if record:
                self.apply(atom)
            else:
                self._write(atom, replay=False)

    def set_goals(self, goals: list[Goal] | tuple[Goal, ...]) -> None:
        """Replace the goal list (add, edit, delete, reorder are all this)."""
        with self.lock:
            new = tuple(goals)
            if new != tuple(self._data.goals):
                self.apply(GoalsAtom(tuple(self._data.goals), new))

    # ----------------------------------------------------------------- persistence
    def snapshot(self) -> MapData:
        """Return a consistent copy of everything, for saving outside the lock."""
        with self.lock:
            d = self._data
            meta = copy.deepcopy(d.meta)
            meta["origin"] = self.origin.copy()
            return MapData(
                vertices=d.vertices,
                faces=d.faces,
                layers=dict(d.layers),  # layer arrays are replaced, never written in place
                vertex_colors=d.vertex_colors,
                texture=d.texture,
                face_labels=self._face_labels.copy(),
                classes=dict(d.classes),
                instances=dict(d.instances),
                goals=list(d.goals),
                meta=meta,
                warnings=list(d.warnings),
            )

    def meta_update(self, **facts: Any) -> None:
        """Record facts about the map's source (no undo step).

        Facts about the source (name, upload) leave the map clean; a change of ``settings``
        (layer parameters, class costs: saved with the map) marks it as having unsaved edits.
        """
        with self.lock:
            if "settings" in facts and facts["settings"] != self._data.meta.get("settings"):
                self.dirty = True
            self._data.meta.update(facts)

    def mark_saved(self, path: str | Path) -> None:
        """Record that the document now lives at ``path`` with nothing unsaved."""
        with self.lock:
            self.path = Path(path)
            self.dirty = False
            self._emit(DocumentSaved(str(path)))


def _sorted_unique(ids: npt.NDArray[np.int64]) -> npt.NDArray[np.int64]:
    """``np.unique(ids)``, fast for big selections.

    numpy >= 2.3 hashes in ``np.unique``: ~80 ms for 250k distinct ids. A stable sort
    (timsort: linear on already sorted ids, as the rubber band returns) and a neighbour
    comparison take under 1 ms (~15 ms when shuffled).
    """
    if len(ids) < 2:
        return ids
    ids = np.sort(ids, kind="stable")
    return ids[np.concatenate(([True], ids[1:] != ids[:-1]))]


def _rgb(color: tuple[int, int, int] | npt.ArrayLike) -> tuple[int, int, int]:
    c = [round(float(x)) for x in np.asarray(color).ravel()[:3]]
    if len(c) != 3 or any(not 0 <= x <= 255 for x in c):
        raise DocumentError(f"a colour needs three values in 0..255, got {color!r}")
    return (c[0], c[1], c[2])
