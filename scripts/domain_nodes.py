#!/usr/bin/env python3
"""Lists the ROS 2 nodes already on this ROS_DOMAIN_ID, one `namespace/name` per line (none: no
output), after waiting --wait-s for discovery. `make demo` runs it before its graph run: a node
left on the domain by another run (a watchdog that zeroes commands, a second simulation) reaches
the demo's topics and spoils its comparison with the in-process run. Exit code 0; 2 when rclpy is
missing or fails to start (a ROS_DOMAIN_ID that is no number: the message says why); rcl ends the
process itself, with its own code and message, on a domain over 232."""
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
    try:
        rclpy.init()
        node = rclpy.create_node(name)
    except Exception as e:  # noqa: BLE001 - rcl's errors have no common type; say which and stop
        print(f"domain_nodes: ROS 2 did not start ({type(e).__name__}: {e})", file=sys.stderr)
        return 2
    try:
        end = time.monotonic() + args.wait_s
        while time.monotonic() < end:
            rclpy.spin_once(node, timeout_sec=0.1)
        for other, ns in sorted(node.get_node_names_and_namespaces()):
            if other != name:
                print(f"{ns.rstrip('/')}/{other}")
    finally:
        node.destroy_node()
        rclpy.shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
