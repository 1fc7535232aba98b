"""Issue 33 item 1's blocker: the initial layout's overlap check is no longer all pairs against all. Past
PAIRWISE_MAX particles a k-d tree finds only the pairs within touching distance (the 128 000-sphere packing
could not be built: the all-pairs check took minutes; benchmarks/results/bench_packing_scale.txt), and an
overlapping layout is refused with the same message, naming the same pair, as the all-pairs check does."""

from __future__ import annotations

import numpy as np
import pytest

from demcheck import case as C
from demcheck.errors import ConfigError


def _layout(n: int, rng: np.random.Generator, plant: list[tuple[int, int]]) -> tuple[np.ndarray, np.ndarray]:
    """n spheres on a jittered grid (none touching), with each planted pair (i, j) moved to overlap."""
    side = int(np.ceil(n ** (1 / 3)))
    g = np.stack(np.meshgrid(*[np.arange(side)] * 3, indexing="ij"), -1).reshape(-1, 3)[:n] * 1e-3
    x = g + rng.uniform(-1e-4, 1e-4, g.shape)
    r = rng.uniform(2e-4, 3e-4, n)
    for i, j in plant:
        x[j] = x[i] + np.array([0.9 * (r[i] + r[j]), 0.0, 0.0])
    return x, r


def _pairwise(x, r):
    for i in range(len(r) - 1):
        d = np.linalg.norm(x[i + 1:] - x[i], axis=1)
        touch = r[i] + r[i + 1:]
        bad = np.flatnonzero(d < touch * (1 - 1e-12))
        if bad.size:
            return i, i + 1 + int(bad[0]), float(touch[bad[0]] - d[bad[0]])
    return None


@pytest.mark.parametrize("plant", [[], [(1500, 1700)], [(3000, 20), (1200, 1800), (1200, 1300)]])
def test_the_tree_finds_the_pair_the_all_pairs_check_finds(plant):
    x, r = _layout(4000, np.random.default_rng(7), plant)
    assert len(r) > C.PAIRWISE_MAX
    assert C._first_overlap(x, r) == _pairwise(x, r)


def _particles(x, r):
    return tuple(C.Particle(material="m", radius=float(r[k]), position=tuple(map(float, x[k]))) for k in range(len(r)))


def test_a_large_overlapping_layout_is_refused_naming_the_first_pair():
    x, r = _layout(3 * C.PAIRWISE_MAX, np.random.default_rng(3), [(2100, 2500), (2100, 2200)])
    with pytest.raises(ConfigError) as e:
        C._check_geometry(_particles(x, r), ())
    first = _pairwise(x, r)
    assert first[:2] == (2100, 2200)
    assert str(e.value).startswith(f"particles.2200.position = {list(map(float, x[2200]))}")
    assert str(e.value).endswith(f"overlaps particle 2100 by {first[2]:.3g} m: particles must not start overlapping")


def test_a_large_layout_is_checked_without_visiting_every_pair(monkeypatch):
    """The check's cost: the all-pairs check computes one row of distances per particle (N − 1 calls), the tree
    one array of the near pairs."""
    x, r = _layout(4000, np.random.default_rng(1), [])
    calls = []
    real = np.linalg.norm
    monkeypatch.setattr(C.np.linalg, "norm", lambda *a, **k: calls.append(1) or real(*a, **k))
    C._check_geometry(_particles(x, r), ())
    assert len(calls) <= 1
