"""The leg classifier: a random forest as plain arrays, stored as an ``.npz`` (no pickle).

The paper classifies laser segments with a random forest (§II-E). It is trained with
scikit-learn's ``RandomForestClassifier`` (``pfctl legs train``) and shipped as numbers only, so
loading a model never runs code (``np.load(..., allow_pickle=False)``) and inference needs numpy
alone: :meth:`LegModel.predict_proba` walks every tree for every sample at once, one level per
step, and averages the leaves' leg probabilities as scikit-learn's ``predict_proba`` does.

File format (``.npz``, version :data:`FORMAT_VERSION`)::

    format            str, "pfctl-leg-forest"
    version           int64 scalar, FORMAT_VERSION
    feature_names     str (f,), the feature columns the forest expects (leg_features.FEATURE_NAMES)
    metadata          str, JSON: data sets, sizes, seed, date, pfctl version, forest parameters
    roots             int32 (t,), the root node of each tree in the node arrays below
    depth             int64 scalar, the deepest path of any tree (levels to walk)
    left, right       int32 (m,), children of each node (global indices); a leaf points to itself
    feature           int32 (m,), the feature tested at each node (0 at leaves)
    threshold         float32 (m,), go left when x[feature] <= threshold (+inf at leaves)
    leaf_probability  float32 (m,), P(leg) at each leaf (the class-1 fraction of its samples)

As in scikit-learn, features are rounded to float32 before they are compared. scikit-learn's
float64 thresholds are stored as the largest float32 not above them, which splits every float32
feature value exactly as the float64 threshold does (and halves the file).

This module turns a model into those bytes and back (:meth:`LegModel.to_bytes`,
:meth:`LegModel.from_bytes`); reading and writing the files, and the model shipped with pfctl,
are the app's (:mod:`pfctl.app.leg_models`).
"""

from __future__ import annotations

import json
import zipfile
from dataclasses import dataclass
from functools import cached_property
from io import BytesIO
from typing import Any

import numpy as np

FORMAT = "pfctl-leg-forest"
FORMAT_VERSION = 1

_ARRAYS = ("roots", "left", "right", "feature", "threshold", "leaf_probability")


@dataclass(frozen=True)
class _Walk:
    """A forest's nodes for the vectorised descent: ``children[2 k]`` is node k's right child
    and ``children[2 k + 1]`` its left one (index ``2 k + go_left``); a leaf is its own child."""

    roots: np.ndarray
    feature: np.ndarray
    children: np.ndarray
    is_leaf: np.ndarray
    leaf_probability: np.ndarray


@dataclass(frozen=True)
class LegModel:
    """A random forest of decision trees over segment features; P(leg) by :meth:`predict_proba`."""

    feature_names: tuple[str, ...]
    roots: np.ndarray
    left: np.ndarray
    right: np.ndarray
    feature: np.ndarray
    threshold: np.ndarray
    leaf_probability: np.ndarray
    depth: int
    metadata: dict[str, Any]

    @property
    def n_trees(self) -> int:
        return len(self.roots)

    @property
    def n_nodes(self) -> int:
        return len(self.left)

    @classmethod
    def from_forest(
        cls, forest: Any, feature_names: tuple[str, ...], metadata: dict[str, Any]
    ) -> LegModel:
        """Copy the trees of a fitted ``sklearn.ensemble.RandomForestClassifier`` with classes
        ``[0, 1]`` (1 = leg) into arrays."""
        classes = list(getattr(forest, "classes_", []))
        if classes != [0, 1]:
            raise ValueError(f"the forest's classes are {classes}, expected [0, 1]")
        roots, lefts, rights, feats, thrs, probs = [], [], [], [], [], []
        offset = 0
        depth = 0
        for est in forest.estimators_:
            t = est.tree_
            m = t.node_count
            leaf = t.children_left == -1
            idx = np.arange(m) + offset
            lefts.append(np.where(leaf, idx, t.children_left + offset))
            rights.append(np.where(leaf, idx, t.children_right + offset))
            feats.append(np.where(leaf, 0, t.feature))
            thrs.append(np.where(leaf, np.inf, t.threshold))
            value = t.value[:, 0, :]
            probs.append(value[:, 1] / np.maximum(value.sum(axis=1), 1e-300))
            roots.append(offset)
            offset += m
            depth = max(depth, int(t.max_depth))
        return cls(
            feature_names=tuple(feature_names),
            roots=np.asarray(roots, dtype=np.int32),
            left=np.concatenate(lefts).astype(np.int32),
            right=np.concatenate(rights).astype(np.int32),
            feature=np.concatenate(feats).astype(np.int32),
            threshold=_float32_floor(np.concatenate(thrs)),
            leaf_probability=np.concatenate(probs).astype(np.float32),
            depth=depth,
            metadata=dict(metadata),
        )

    def predict_proba(self, features: np.ndarray) -> np.ndarray:
        """P(leg) ``(n,)`` for feature rows ``(n, f)``: every sample descends every tree at once
        (at most ``depth`` vectorised steps, fewer once every sample sits on a leaf), then the
        leaves' probabilities are averaged."""
        x = np.ascontiguousarray(features, dtype=np.float32)
        if x.ndim != 2 or x.shape[1] != len(self.feature_names):
            raise ValueError(
                f"expected features of shape (n, {len(self.feature_names)}), got {x.shape}"
            )
        n, f = x.shape
        if n == 0:
            return np.empty(0)
        walk = self._walk
        values = x.ravel()
        row = (np.arange(n, dtype=np.intp) * f)[:, None]
        node = np.broadcast_to(walk.roots, (n, self.n_trees)).copy()
        for level in range(self.depth):
            go_left = values.take(row + walk.feature.take(node)) <= self.threshold.take(node)
            node = walk.children.take(2 * node + go_left)
            if level % 4 == 3 and walk.is_leaf.take(node).all():
                break
        return walk.leaf_probability.take(node).mean(axis=1)

    @cached_property
    def _walk(self) -> _Walk:
        """The node arrays as :meth:`predict_proba` walks them (built on first use)."""
        nodes = np.arange(self.n_nodes)
        return _Walk(
            roots=self.roots.astype(np.intp),
            feature=self.feature.astype(np.intp),
            children=np.stack([self.right, self.left], axis=1).ravel().astype(np.intp),
            is_leaf=self.left == nodes,
            leaf_probability=self.leaf_probability.astype(np.float64),
        )

    def to_bytes(self) -> bytes:
        """The model as ``.npz`` bytes (compressed)."""
        buf = BytesIO()
        np.savez_compressed(
            buf,
            format=np.array(FORMAT),
            version=np.array(FORMAT_VERSION, dtype=np.int64),
            feature_names=np.array(self.feature_names, dtype=str),
            metadata=np.array(json.dumps(self.metadata, sort_keys=True)),
            depth=np.array(self.depth, dtype=np.int64),
            roots=self.roots,
            left=self.left,
            right=self.right,
            feature=self.feature,
            threshold=self.threshold,
            leaf_probability=self.leaf_probability,
        )
        return buf.getvalue()

    @classmethod
    def from_bytes(cls, data: bytes, expected_features: tuple[str, ...] | None = None) -> LegModel:
        """The model in :meth:`to_bytes`'s bytes.

        ValueError (one line) for bytes that are not a leg model (corrupt, foreign, pickled), a
        newer format, damaged or inconsistent tree arrays, or (with ``expected_features``) a
        model trained on other features.
        """
        try:
            with np.load(BytesIO(data), allow_pickle=False) as npz:
                arrays = {name: npz[name] for name in npz.files}
        except (OSError, ValueError, EOFError, zipfile.BadZipFile) as err:
            raise ValueError(f"not a leg model (.npz without pickles): {err}") from None
        if str(arrays.get("format", "")) != FORMAT:
            raise ValueError(f"not a leg model: the file has no format '{FORMAT}'")
        try:
            version = int(arrays["version"])
        except (KeyError, ValueError, TypeError) as err:
            raise ValueError(f"damaged leg model: {err}") from None
        if version > FORMAT_VERSION:
            raise ValueError(
                f"leg model format {version} is newer than this pfctl reads "
                f"({FORMAT_VERSION}); upgrade pfctl or retrain with `pfctl legs train`"
            )
        try:
            names = tuple(str(s) for s in arrays["feature_names"])
            metadata = json.loads(str(arrays["metadata"]))
            model = cls(
                feature_names=names,
                roots=np.asarray(arrays["roots"], dtype=np.int32),
                left=np.asarray(arrays["left"], dtype=np.int32),
                right=np.asarray(arrays["right"], dtype=np.int32),
                feature=np.asarray(arrays["feature"], dtype=np.int32),
                threshold=np.asarray(arrays["threshold"], dtype=np.float32),
                leaf_probability=np.asarray(arrays["leaf_probability"], dtype=np.float32),
                depth=int(arrays["depth"]),
                metadata=metadata if isinstance(metadata, dict) else {},
            )
        except (KeyError, ValueError, TypeError) as err:
            raise ValueError(f"damaged leg model: {err}") from None
        _check(model)
        if expected_features is not None and model.feature_names != tuple(expected_features):
            raise ValueError(
                f"the leg model was trained on features {', '.join(model.feature_names)}; "
                f"this pfctl computes {', '.join(expected_features)} "
                "(retrain with `pfctl legs train`)"
            )
        return model


def _float32_floor(values: np.ndarray) -> np.ndarray:
    """The largest float32 ≤ each float64 value (x32 ≤ t64 ⟺ x32 ≤ floor32(t64))."""
    v = np.asarray(values, dtype=np.float64)
    out = v.astype(np.float32)
    up = out.astype(np.float64) > v
    out[up] = np.nextafter(out[up], np.float32(-np.inf))
    return out


def _check(model: LegModel) -> None:
    """Refuse node arrays that would index out of bounds or do not line up."""
    m = model.n_nodes
    sizes = {len(getattr(model, a)) for a in _ARRAYS[1:]}
    ok = (
        sizes == {m}
        and m > 0
        and model.n_trees > 0
        and model.depth >= 0
        and np.all((model.roots >= 0) & (model.roots < m))
        and np.all((model.left >= 0) & (model.left < m))
        and np.all((model.right >= 0) & (model.right < m))
        and np.all((model.feature >= 0) & (model.feature < max(len(model.feature_names), 1)))
    )
    if not ok:
        raise ValueError("damaged leg model: inconsistent tree arrays")


__all__ = ["FORMAT", "FORMAT_VERSION", "LegModel"]
