"""Trees and meshes as arguments of multiprocessing.Pool (spawn and fork) and
concurrent.futures.ProcessPoolExecutor tasks: they travel by pickle, and the answers that come
back (also pickled) are the in-process answers bit for bit."""
import concurrent.futures
import multiprocessing
import pathlib

import numpy as np
import pytest
import tightbvh
from conftest import pose_matrix, rotation

POSES = [
    pose_matrix(rotation([1, 2, 3], 0.7), [0.1, 0.0, 0.05]),
    pose_matrix(rotation([0, 0, 1], 0.3), [0.9, 0.1, 0.0]),
    pose_matrix(rotation([1, -1, 0], 2.0), [0.3, 0.4, -0.2]),
    pose_matrix(rotation([2, 0, 1], 1.1), [-0.2, 0.1, 0.3]),
    pose_matrix(np.eye(3), [5.0, 0.0, 0.0]),
]


# Tasks: module-level functions, so that spawned workers import them from this file by name.
def queries(tree_a, tree_b, poses, mesh_a=None, mesh_b=None):
    """collide (all pairs), distance and the two batch calls on `poses`: plain tuples of arrays
    and numbers, and the result objects themselves (pickled back to the parent)."""
    out = []
    for pose in poses:
        hit = tightbvh.collide(tree_a, mesh_a, None, tree_b, mesh_b, pose, all_pairs=True)
        gap = tightbvh.distance(tree_a, mesh_a, None, tree_b, mesh_b, pose)
        out.append((hit, gap, hit.pairs, gap.distance, gap.point_a, gap.point_b))
    stack = np.stack(poses)
    batch = tightbvh.collide_batch(tree_a, mesh_a, None, tree_b, mesh_b, stack, all_pairs=True, threads=1)
    distances = tightbvh.distance_batch(tree_a, mesh_a, None, tree_b, mesh_b, stack, threads=1)
    return out, batch, distances


def same_bits(a, b):
    a, b = np.asarray(a), np.asarray(b)
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


def assert_same_answers(expected, got):
    (rows, batch, distances), (rows_got, batch_got, distances_got) = expected, got
    assert len(rows) == len(rows_got)
    for (hit, gap, *arrays), (hit_got, gap_got, *arrays_got) in zip(rows, rows_got):
        assert (hit.hit, hit.stats, hit.inside) == (hit_got.hit, hit_got.stats, hit_got.inside)
        assert same_bits(hit.pairs, hit_got.pairs)
        assert (gap.triangles, gap.stats, gap.beyond_upper_bound) == (gap_got.triangles, gap_got.stats,
                                                                      gap_got.beyond_upper_bound)
        assert same_bits(gap.distance, gap_got.distance) and same_bits(gap.point_a_local, gap_got.point_a_local)
        assert all(same_bits(x, y) for x, y in zip(arrays, arrays_got))
    assert all(same_bits(x, y) for x, y in zip(batch, batch_got))
    assert all(same_bits(x, y) for x, y in zip(distances, distances_got))


@pytest.fixture(scope="module")
def trees(elephant, knot):
    return tightbvh.build(elephant, fitter="approx"), tightbvh.build(knot)


@pytest.fixture(scope="module")
def expected(trees):
    answers = [queries(*trees, POSES[i::2]) for i in range(2)]
    assert any(row[0].hit for answer in answers for row in answer[0])
    assert any(row[1].distance > 0 for answer in answers for row in answer[0])
    return answers


@pytest.mark.parametrize("method", ["spawn", "fork"])
def test_pool_answers_as_in_process(trees, expected, method):
    with multiprocessing.get_context(method).Pool(2) as pool:
        got = pool.starmap(queries, [(*trees, POSES[i::2]) for i in range(2)])
    for e, g in zip(expected, got):
        assert_same_answers(e, g)


@pytest.mark.parametrize("method", ["spawn", "fork"])
def test_pool_with_loaded_trees_and_meshes_as_arguments(trees, expected, elephant, knot, tmp_path, method):
    # Trees read from files carry no mesh: the meshes travel as arguments of their own.
    paths = [tmp_path / "a.tree", tmp_path / "b.tree"]
    for tree, path in zip(trees, paths):
        tree.save(path)
    loaded = [tightbvh.Tree.load(path) for path in paths]
    with multiprocessing.get_context(method).Pool(2) as pool:
        got = pool.starmap(queries, [(*loaded, POSES[i::2], elephant, knot) for i in range(2)])
    for e, g in zip(expected, got):
        assert_same_answers(e, g)


def test_process_pool_executor_answers_as_in_process(trees, expected):
    context = multiprocessing.get_context("spawn")
    with concurrent.futures.ProcessPoolExecutor(max_workers=2, mp_context=context) as executor:
        futures = [executor.submit(queries, *trees, POSES[i::2]) for i in range(2)]
        got = [f.result() for f in futures]
    for e, g in zip(expected, got):
        assert_same_answers(e, g)


def test_process_pool_executor_default_context_map(trees, expected):
    with concurrent.futures.ProcessPoolExecutor(max_workers=2) as executor:
        got = list(executor.map(queries, [trees[0]] * 2, [trees[1]] * 2, [POSES[0::2], POSES[1::2]]))
    for e, g in zip(expected, got):
        assert_same_answers(e, g)


def test_the_module_workers_import_is_this_build():
    # Spawned workers find tightbvh on the parent's sys.path (multiprocessing passes it along):
    # the same built module, not some other installed copy.
    with multiprocessing.get_context("spawn").Pool(1) as pool:
        assert pool.apply(module_file) == module_file()


def module_file():
    return str(pathlib.Path(tightbvh.__file__).resolve())
