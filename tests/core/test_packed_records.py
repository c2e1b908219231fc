"""The packed record store: a list of records to its readers, rows of numpy arrays inside."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from pfctl.core.packed_records import CHUNK_ROWS, PackedRecords, RecordCodec, StringTable


class PairCodec(RecordCodec[tuple[str | None, float]]):
    dtype = np.dtype([("name", "i4"), ("value", "f8")])

    def __init__(self) -> None:
        self.strings = StringTable()

    def encode(self, record: tuple[str | None, float]) -> tuple[int, float]:
        return self.strings.encode(record[0]), record[1]

    def decode(self, row: tuple[int, float]) -> tuple[str | None, float]:
        return self.strings.decode(row[0]), row[1]


def records(n: int) -> list[tuple[str | None, float]]:
    rng = np.random.default_rng(0)
    names = ["alice", "bob", None]
    return [(names[i % 3], float(rng.normal())) for i in range(n)]


def test_reads_back_what_was_appended_across_chunks_exactly() -> None:
    given = records(2 * CHUNK_ROWS + 5)
    store = PackedRecords(PairCodec(), given)
    assert len(store) == len(given)
    assert list(store) == given  # floats bit for bit, None kept
    assert store == given and store[-1] == given[-1] and store[CHUNK_ROWS] == given[CHUNK_ROWS]
    assert store[3:9] == given[3:9] and store[::-1][:3] == given[::-1][:3]
    assert store.column("value").tolist() == [v for _, v in given]
    with pytest.raises(IndexError):
        store[len(given)]


def test_list_operations() -> None:
    given = records(CHUNK_ROWS + 1)
    store = PackedRecords(PairCodec())
    assert not store and store.column("value").shape == (0,)
    store += given[:10]
    store.extend(given[10:])
    store.append(("carol", 1.5))
    assert store.pop() == ("carol", 1.5)
    assert store.pop() == given[-1]  # back across the chunk boundary
    store.append(given[-1])
    assert store == given
    store[0] = ("dave", -2.0)
    assert store[0] == ("dave", -2.0) and store[1:] == given[1:]
    assert pickle.loads(pickle.dumps(store)) == store


def test_a_row_is_a_few_bytes_and_a_string_is_stored_once() -> None:
    store = PackedRecords(PairCodec(), records(3 * CHUNK_ROWS))
    assert store.nbytes == 3 * CHUNK_ROWS * PairCodec.dtype.itemsize
    table = StringTable()
    assert [table.encode(s) for s in ("a", "b", "a", None)] == [0, 1, 0, -1]
    assert table.decode_all(np.array([1, -1, 0])) == ["b", None, "a"]


class ListStore:
    """A chunk store that keeps copies, to see what was handed over."""

    def __init__(self) -> None:
        self.chunks: list[np.ndarray] = []

    def put(self, chunk: np.ndarray) -> np.ndarray:
        self.chunks.append(chunk.copy())
        return self.chunks[-1]


def test_full_chunks_go_to_the_store_and_read_back_the_same() -> None:
    given = records(3 * CHUNK_ROWS + 7)
    store = PackedRecords(PairCodec(), given[: CHUNK_ROWS + 3])
    chunks = ListStore()
    store.spill_to(chunks)
    assert len(chunks.chunks) == 1  # the one already full; the one being filled stays
    store.extend(given[CHUNK_ROWS + 3 :])
    assert len(chunks.chunks) == 3
    assert store == given and store.column("value").tolist() == [v for _, v in given]
    store[5] = ("erin", 3.0)
    assert store[5] == ("erin", 3.0) and chunks.chunks[0][5]["value"] == 3.0
    assert pickle.loads(pickle.dumps(store))[5] == ("erin", 3.0)
