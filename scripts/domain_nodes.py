#!/usr/bin/env python3
"""Lists the ROS 2 nodes already on this ROS_DOMAIN_ID, one `namespace/name` per line (none: no
output), after waiting --wait-s for discovery. `make demo` runs it before its graph run: a node
left on the domain by another run (a watchdog that zeroes commands, a second simulation) reaches
the demo's topics and spoils its comparison with the in-process run. Exit code 0, or 2 when ROS 2
cannot start (rclpy missing or failing: the message says why)."""
import argparse
import os
import sys
import time


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--wait-s", type=float, default=1.5, help="discovery time before listing [s] (default 1.5)")
    args = parser.parse_args()
    try:
        import rclpy
    except ImportError as e:
        print(f"domain_nodes: no rclpy ({e}); source .deps/env.sh", file=sys.stderr)
        return 2
    name = f"domain_probe_{os.getpid()}"
    rclpy.init()
    try:
        node = rclpy.create_node(name)
        end = time.monotonic() + args.wait_s
        while time.monotonic() < end:
            rclpy.spin_once(node, timeout_sec=0.1)
        for other, ns in sorted(node.get_node_names_and_namespaces()):
            if other != name:
                print(f"{ns.rstrip('/')}/{other}")
        node.destroy_node()
    finally:
        rclpy.shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
