"""WorkerPool's grouped dispatch: a worker keeps to the group (an evaluation's scene) it is on.

An evaluation worker builds a scene's geometry once and plays that scene's episodes; sent the
episodes in dataset order, two workers would each build every scene. The schedule here is
checked as a plain sequence of requests, against the rule written out by hand.
"""

import os

from pointnav_core.utils.workers import WorkerPool, _GroupedQueue


def _items(groups: str) -> list[tuple[int, str]]:
    return list(enumerate(groups))


def _drain(queue: _GroupedQueue, workers: list[int]) -> dict[int, str]:
    """Ask for items in the order ``workers`` (cycled) until none are left."""
    took: dict[int, str] = {w: "" for w in set(workers)}
    k = 0
    while (entry := queue.take(workers[k % len(workers)])) is not None:
        took[workers[k % len(workers)]] += entry[1]
        k += 1
    return took


def test_each_worker_keeps_to_its_group():
    took = _drain(_GroupedQueue(_items("AAAABBBBCCCC"), group=str), [0, 1])
    # 0 takes A, 1 takes the first group nobody is on (B); both keep to theirs; C goes to
    # whichever frees first (0), and the last items of C are shared with 1, now free.
    assert took == {0: "AAAACC", 1: "BBBBCC"}


def test_items_of_a_group_keep_their_order_and_none_is_lost():
    items = _items("ABABCCAB")
    queue = _GroupedQueue(items, group=str)
    got = []
    while (entry := queue.take(len(got) % 3)) is not None:
        got.append(entry)
    assert sorted(got) == items
    for g in "ABC":
        keys = [k for k, v in got if v == g]
        assert keys == sorted(keys)


def test_a_lone_worker_plays_groups_in_first_seen_order():
    took = _drain(_GroupedQueue(_items("BABCA"), group=str), [0])
    assert took == {0: "BBAAC"}


def _no_state() -> None:
    return None


def _where(_state: None, item: str) -> tuple[int, str]:
    return os.getpid(), item


def test_the_pool_runs_every_grouped_item_once():
    items = list(enumerate("AAABBBCCD"))
    with WorkerPool(2, _no_state, (), _where) as pool:
        out = dict(pool.imap_unordered(items, group=str))
    assert sorted(out) == list(range(len(items)))
    assert [out[k][1] for k in range(len(items))] == list("AAABBBCCD")
