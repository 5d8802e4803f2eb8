"""The Zarr store of a tiled run: one group per tile, written whole then marked complete.

Layout (Zarr v3):
    <root>/                 attrs["vpds_tiling"]: the run's parameters and their token
    <root>/tiles/<k>/points (n, d) float64   the tile's own samples, in insertion order
    <root>/tiles/<k>/radius (n,)   float64   r at each sample (unscaled)
    <root>/tiles/<k>/t      (n,)   float64   the scale at which it was inserted
    <root>/tiles/<k>        attrs {"count": n, "phase": p, "complete": true}, written last
Tiles hold different counts, so each has its arrays. A tile whose group is not marked complete
(a worker killed while writing it) is written again by a resumed run: every file is replaced
atomically (Zarr's local store renames a finished temporary file), and a tile's bytes depend on
the seed and its dependencies alone, so a rewrite gives the same bytes."""
from __future__ import annotations

import json
import os
import uuid
from pathlib import Path
from typing import Any, Iterator, Literal, Mapping, Optional, Sequence, Union, cast

import numpy as np
import numpy.typing as npt

__all__ = ["TileStore"]

FORMAT = 1
_ROWS_PER_CHUNK = 1 << 20


def _json(doc: Mapping[str, Any]) -> bytes:
    return json.dumps(doc, separators=(",", ":")).encode()


def _write_file(path: Path, data: bytes) -> None:
    """Replace path atomically: a temporary file of a unique name (two workers may write one
    tile, a retried task beside one thought dead, on a shared filesystem) renamed over it, and
    removed if the write fails; its directory exists."""
    tmp = path.with_name(f".{path.name}.{uuid.uuid4().hex}.tmp")
    try:
        tmp.write_bytes(data)
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def _write_array(path: Path, arr: npt.NDArray[np.float64]) -> None:
    """One float64 array in the Zarr v3 layout that zarr-python writes for it (regular chunks of
    _ROWS_PER_CHUNK rows, little-endian bytes then zstd level 0), written directly: through
    zarr, the three arrays of a tile cost about 30 ms (its event-loop round trips), more than the
    run of a tile of a few thousand samples."""
    from numcodecs import Zstd
    rows = max(1, min(len(arr), _ROWS_PER_CHUNK))
    codec = Zstd(level=0)
    os.makedirs(path / "c" / "0" if arr.ndim > 1 else path / "c", exist_ok=True)
    for i, start in enumerate(range(0, len(arr), rows)):
        key = ["c", str(i)] + ["0"] * (arr.ndim - 1)
        if i and arr.ndim > 1:
            os.makedirs(path.joinpath(*key[:-1]), exist_ok=True)
        chunk = np.zeros((rows,) + arr.shape[1:], dtype="<f8")  # the last chunk padded with the fill
        part = arr[start:start + rows]
        chunk[:len(part)] = part
        _write_file(path.joinpath(*key), bytes(codec.encode(chunk.tobytes())))
    _write_file(path / "zarr.json", _json({
        "shape": list(arr.shape), "data_type": "float64",
        "chunk_grid": {"name": "regular", "configuration": {"chunk_shape": [rows, *arr.shape[1:]]}},
        "chunk_key_encoding": {"name": "default", "configuration": {"separator": "/"}},
        "fill_value": 0.0,
        "codecs": [{"name": "bytes", "configuration": {"endian": "little"}},
                   {"name": "zstd", "configuration": {"level": 0, "checksum": False}}],
        "attributes": {}, "zarr_format": 3, "node_type": "array", "storage_transformers": []}))


class TileStore:
    """Read and write the tiles of one run. `TileStore(path)` opens an existing store."""

    def __init__(self, path: Union[str, Path], mode: Literal["r", "r+", "a", "w", "w-"] = "r") -> None:
        import zarr
        self.path = str(path)
        self._root = zarr.open_group(self.path, mode=mode)
        info = self._root.attrs.get("vpds_tiling")
        if info is None:
            raise ValueError(f"{self.path}: not a vpds tile store (no vpds_tiling attribute)")
        self.info: dict[str, Any] = dict(cast(Mapping[str, Any], info))  # a JSON object: create() writes it
        self.d = int(self.info["params"]["d"])
        self.count = int(self.info["count"])
        self.phases = list(self.info["phases"])

    @classmethod
    def create(cls, path: Union[str, Path], params: dict[str, Any], token: str,
               phases: Sequence[int]) -> "TileStore":
        """A new store, or the existing one when it holds the same run (same token)."""
        import zarr
        p = Path(path)
        if (p / "zarr.json").exists():
            store = cls(path, mode="r+")
            if store.info.get("token") != token:
                old = store.info.get("params", {})
                diff = sorted(k for k in set(old) | set(params) if old.get(k) != params.get(k))
                raise ValueError(f"{path} holds another run (different {', '.join(diff) or 'sizing'}); "
                                 "resume needs the same parameters: use a new path or overwrite=True")
            return store
        root = zarr.open_group(str(path), mode="w")
        root.create_group("tiles")
        root.attrs["vpds_tiling"] = {"format": FORMAT, "token": token, "params": params,
                                     "count": len(phases), "phases": [int(v) for v in phases]}
        return cls(path, mode="r+")

    # -- tiles -------------------------------------------------------------------------------------
    def _node(self, key: str) -> Any:
        """The group or array at `key`: zarr types it as either, the layout above says which."""
        return self._root[key]

    def _group(self, tile: int) -> Any:
        """The tile's group, or None."""
        try:
            return self._node(f"tiles/{int(tile)}")
        except KeyError:
            return None

    def complete(self, tile: int) -> bool:
        """Whether the tile is written whole. Reads its group's metadata file directly: cheap."""
        meta = Path(self.path) / "tiles" / str(int(tile)) / "zarr.json"
        try:
            return bool(json.loads(meta.read_text()).get("attributes", {}).get("complete", False))
        except (OSError, ValueError):
            return False

    def missing(self) -> list[int]:
        return [k for k in range(self.count) if not self.complete(k)]

    def write(self, tile: int, x: npt.NDArray[np.float64], r: npt.NDArray[np.float64],
              t: npt.NDArray[np.float64]) -> None:
        """The tile's arrays (points (n, d), radius and t (n,)), then its completion mark (a reader
        never sees a partial tile)."""
        base = Path(self.path) / "tiles" / str(int(tile))
        n = len(x)
        for name, arr in (("points", np.ascontiguousarray(x, dtype=np.float64).reshape(n, self.d)),
                          ("radius", np.ascontiguousarray(r, dtype=np.float64).reshape(n)),
                          ("t", np.ascontiguousarray(t, dtype=np.float64).reshape(n))):
            _write_array(base / name, arr)
        _write_file(base / "zarr.json", _json({
            "attributes": {"count": int(n), "phase": int(self.phases[int(tile)]), "complete": True},
            "zarr_format": 3, "node_type": "group"}))

    def read(self, tile: int) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """(points (n, d), radius (n,), t (n,)) of a complete tile."""
        if not self.complete(tile):
            raise KeyError(f"tile {tile} of {self.path} is not complete")
        g = self._group(tile)
        return g["points"][...], g["radius"][...], g["t"][...]

    def read_points(self, tile: int) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """(points (n, d), radius (n,)) of a complete tile: what a dependent tile's run needs."""
        if not self.complete(tile):
            raise KeyError(f"tile {tile} of {self.path} is not complete")
        return self._node(f"tiles/{int(tile)}/points")[...], self._node(f"tiles/{int(tile)}/radius")[...]

    def tile_count(self, tile: int) -> int:
        return int(self._group(tile).attrs["count"])

    # -- streaming back ----------------------------------------------------------------------------
    def order(self) -> list[int]:
        """The run's insertion order of tiles: by phase, then index."""
        return sorted(range(self.count), key=lambda k: (self.phases[k], k))

    def iter_tiles(self, order: str = "insertion"
                   ) -> Iterator[tuple[int, npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64]]]:
        """(tile, points (n, d), radius (n,), t (n,)) one tile at a time: memory holds one tile,
        whatever the total. order="insertion" (phase, then index: the order in which the union
        is conflict-free under any rule) or "index"."""
        tiles = self.order() if order == "insertion" else range(self.count)
        for k in tiles:
            x, r, t = self.read(k)
            yield k, x, r, t

    @property
    def total(self) -> int:
        """Samples in the complete tiles."""
        return sum(self.tile_count(k) for k in range(self.count) if self.complete(k))

    def to_numpy(self, order: str = "insertion"
                 ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """Every sample at once, (points (n, d), radius (n,), t (n,)) (for runs that fit in
        memory)."""
        parts = list(self.iter_tiles(order))
        if not parts:
            return np.empty((0, self.d)), np.empty(0), np.empty(0)
        return (np.concatenate([p[1] for p in parts]), np.concatenate([p[2] for p in parts]),
                np.concatenate([p[3] for p in parts]))

    def __repr__(self) -> str:
        done = self.count - len(self.missing())
        return f"TileStore({self.path!r}: {done}/{self.count} tiles complete, d = {self.d})"

    @property
    def params(self) -> dict[str, Any]:
        return dict(self.info["params"])
