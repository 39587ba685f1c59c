"""Regenerate scenarios/worlds/scanned_mine.ply, the "scanned mine" test asset.

Usage: python bench/make_scanned_mine.py [OUT.ply]

The asset is a ~150 m tunnel_network mesh with 2 cm scan noise, decimated,
written Y-up and in centimetres (load with scale 0.01, up_axis "y").
"""

import sys
import time

from delve.sim import worldgen


def main() -> None:
    """Write the asset and print its size and what it loads back as."""
    out = sys.argv[1] if len(sys.argv) > 1 else worldgen.SCANNED_MINE_PATH
    t0 = time.perf_counter()
    path = worldgen.write_scanned_mine(out)
    world = worldgen.scanned_mine(path=path)
    print(f"wrote {path} ({path.stat().st_size / 1e6:.2f} MB, "
          f"{len(world.mesh.triangles)} triangles) in {time.perf_counter() - t0:.1f} s; "
          f"loads as {world}, free volume {world.free_volume_m3:.0f} m^3, "
          f"start {world.start.round(2).tolist()}")


if __name__ == "__main__":
    main()
