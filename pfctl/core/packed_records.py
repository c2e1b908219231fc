"""A growing sequence of small records kept as rows of numpy structured arrays.

An episode appends a few records per tick for as long as it runs (:mod:`pfctl.core.episode`): as
Python objects each costs kilobytes (an instance dictionary, a boxed float per number, a tuple
per pair), so an hour on a robot would hold hundreds of megabytes of them. :class:`PackedRecords`
stores each record as one fixed-size row instead (its numbers as float64/int64, exactly; its
strings as indices into a :class:`StringTable`) in chunks of :data:`CHUNK_ROWS` rows, and makes the
record again when it is read. What it stores and how is a :class:`RecordCodec`'s; the sequence is
the same to its readers as a list of the records.

Packed, a tick still costs a few hundred bytes. Given a :class:`ChunkStore` (:meth:`spill_to`),
each chunk that fills up is handed to it, and the store gives back an array to use instead, e.g. a
memory map of the rows written to a file (:mod:`pfctl.app.spill`): a run of hours then keeps only
the chunk being filled in memory, and reads the others back when they are read.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator, Sequence
from typing import Any, Generic, Protocol, TypeVar, overload

import numpy as np

R = TypeVar("R")

#: Rows per chunk: the store grows by one chunk at a time, never copying the rows it has.
CHUNK_ROWS = 4096
#: The stored index of ``None`` in a string or integer column.
NONE_INDEX = -1


class StringTable:
    """Strings (and ``None``) as small integers: each distinct string stored once."""

    def __init__(self) -> None:
        self._index: dict[str, int] = {}
        self._strings: list[str] = []

    def encode(self, value: str | None) -> int:
        """The index of ``value`` (:data:`NONE_INDEX` for ``None``), added when new."""
        if value is None:
            return NONE_INDEX
        index = self._index.get(value)
        if index is None:
            index = self._index[value] = len(self._strings)
            self._strings.append(value)
        return index

    def decode(self, index: int) -> str | None:
        """The string stored at ``index``."""
        return None if index == NONE_INDEX else self._strings[index]

    def decode_all(self, indices: np.ndarray) -> list[str | None]:
        """The strings stored at ``indices``, in order."""
        table: list[str | None] = [*self._strings, None]  # NONE_INDEX (-1) picks the last
        return [table[i] for i in indices.tolist()]


class RecordCodec(Generic[R]):
    """How a record becomes one row of :attr:`dtype` and back: ``encode`` returns the row's
    values in the dtype's field order, ``decode`` gets them back as Python scalars. A codec may
    keep state shared by all the rows of one store (a :class:`StringTable`, a nested store)."""

    dtype: np.dtype

    def encode(self, record: R) -> tuple[Any, ...]:
        raise NotImplementedError

    def decode(self, row: tuple[Any, ...]) -> R:
        raise NotImplementedError


class ChunkStore(Protocol):
    """Where full chunks go (module docstring)."""

    def put(self, chunk: np.ndarray) -> np.ndarray:
        """Keep ``chunk``'s rows; an array of the same rows (writable) to use in its place."""
        ...


class PackedRecords(Sequence[R]):
    """A list-like sequence of records stored by ``codec`` (module docstring): ``append``,
    ``extend``/``+=``, ``pop`` of the last one, item assignment, indexing and slices (a slice is
    a list of records). Equal to any sequence of equal records."""

    def __init__(self, codec: RecordCodec[R], records: Iterable[R] = ()) -> None:
        self._codec = codec
        self._chunks: list[np.ndarray] = []
        self._length = 0
        self._store: ChunkStore | None = None
        self.extend(records)

    def __len__(self) -> int:
        return self._length

    def _locate(self, index: int) -> tuple[np.ndarray, int]:
        if index < 0:
            index += self._length
        if not 0 <= index < self._length:
            raise IndexError("record index out of range")
        return self._chunks[index // CHUNK_ROWS], index % CHUNK_ROWS

    @overload
    def __getitem__(self, index: int) -> R: ...

    @overload
    def __getitem__(self, index: slice) -> list[R]: ...

    def __getitem__(self, index: int | slice) -> R | list[R]:
        if isinstance(index, slice):
            return [self[i] for i in range(*index.indices(self._length))]
        chunk, row = self._locate(index)
        return self._codec.decode(chunk[row].item())

    def __setitem__(self, index: int, record: R) -> None:
        chunk, row = self._locate(index)
        chunk[row] = self._codec.encode(record)

    def __iter__(self) -> Iterator[R]:
        decode = self._codec.decode
        for start in range(0, self._length, CHUNK_ROWS):
            chunk = self._chunks[start // CHUNK_ROWS]
            for row in chunk[: min(CHUNK_ROWS, self._length - start)].tolist():
                yield decode(row)

    def append(self, record: R) -> None:
        """Add ``record`` at the end."""
        row = self._length % CHUNK_ROWS
        if row == 0:
            if self._chunks and self._store is not None:
                self._chunks[-1] = self._store.put(self._chunks[-1])
            self._chunks.append(np.empty(CHUNK_ROWS, dtype=self._codec.dtype))
        self._chunks[-1][row] = self._codec.encode(record)
        self._length += 1

    def extend(self, records: Iterable[R]) -> None:
        """Add ``records`` at the end, in order."""
        for record in records:
            self.append(record)

    def __iadd__(self, records: Iterable[R]) -> PackedRecords[R]:
        self.extend(records)
        return self

    def pop(self) -> R:
        """Remove and return the last record."""
        record = self[-1]
        self._length -= 1
        if self._length % CHUNK_ROWS == 0:
            self._chunks.pop()
        return record

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Sequence) or isinstance(other, str):
            return NotImplemented
        return len(self) == len(other) and all(a == b for a, b in zip(self, other, strict=True))

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return f"PackedRecords({list(self)!r})"

    def spill_to(self, store: ChunkStore) -> None:
        """From now on hand each chunk that fills up to ``store`` (module docstring); the full
        ones already here go now."""
        self._store = store
        full = self._length // CHUNK_ROWS
        for i in range(full if self._length % CHUNK_ROWS else full - 1):
            self._chunks[i] = store.put(self._chunks[i])

    def __getstate__(self) -> dict[str, Any]:
        state = self.__dict__.copy()
        state["_chunks"] = [np.array(chunk) for chunk in self._chunks]  # the rows, not a map
        state["_store"] = None
        return state

    @property
    def codec(self) -> RecordCodec[R]:
        """How the records are stored (its string table, nested stores)."""
        return self._codec

    def column(self, name: str) -> np.ndarray:
        """Field ``name`` of every row, in order (a new array): how a reader of many records
        takes one value of each without making the records."""
        if not self._chunks:
            return np.zeros(0, dtype=self._codec.dtype[name])
        whole = np.concatenate([chunk[name] for chunk in self._chunks])
        return whole[: self._length]

    @property
    def nbytes(self) -> int:
        """Bytes the rows take (whole chunks, the codec's own state aside)."""
        return sum(chunk.nbytes for chunk in self._chunks)


def packed_factory(codec: Callable[[], RecordCodec[R]]) -> Callable[[], PackedRecords[R]]:
    """A dataclass ``default_factory``: an empty store with a fresh codec."""
    return lambda: PackedRecords(codec())


__all__ = [
    "CHUNK_ROWS",
    "NONE_INDEX",
    "ChunkStore",
    "PackedRecords",
    "RecordCodec",
    "StringTable",
    "packed_factory",
]
