"""The decomposition cache across processes: set in one process, or named by the environment
for every process that imports impulse (a sweep's or a takes search's workers)."""

import os
import subprocess
import sys

#: A fresh process that splits an L-shaped block (a closed, non-convex mesh) into convex parts
#: and prints how many; the cache directory, if any, is whatever the process was given.
SPLIT = """
import impulse
corners = [(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)]
vertices = [[x, y, z] for z in (0.0, 1.0) for x, y in corners]
n = len(corners)
indices = [[0, i + 1, i] for i in range(1, n - 1)] + [[n, n + i, n + i + 1] for i in range(1, n - 1)]
for i in range(n):
    j = (i + 1) % n
    indices += [[i, j, n + j], [i, n + j, n + i]]
shape = impulse.Shape.from_dict({"type": "trimesh", "vertices": vertices, "indices": indices})
print(len(shape.convex_parts()))
"""


def _split(environment):
    done = subprocess.run(
        [sys.executable, "-c", SPLIT], env=environment, capture_output=True, text=True, check=True
    )
    return int(done.stdout.split()[-1])


def test_the_environment_names_a_cache_that_a_later_process_reads(tmp_path):
    cache = tmp_path / "cache"
    environment = dict(os.environ, IMPULSE_DECOMPOSITION_CACHE=str(cache))
    parts = _split(environment)
    assert parts >= 2, "an L is not convex"
    kept = os.listdir(cache)
    assert len(kept) == 1 and kept[0].endswith(".vhacd")
    # Read, not split again: a split would write the file anew.
    path = cache / kept[0]
    long_ago = 946_684_800
    os.utime(path, (long_ago, long_ago))
    assert _split(environment) == parts
    assert os.stat(path).st_mtime == long_ago

