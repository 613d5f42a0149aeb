"""Two hosts on one machine: two network namespaces joined by a veth pair (10.213.<k>.1/24 and .2),
for running the graph's nodes "across hosts" as DDS sees it (test/test_netns.py, the
ros_latency_netns_p50_us figure of scripts/bench_graph.py). Needs root and `ip` (iproute2).

    with TwoHosts() as hosts:
        sim = subprocess.Popen(hosts.command("a", ["mujoco_sim", ...]), env=hosts.env())

Discovery runs over the veth with ROS_AUTOMATIC_DISCOVERY_RANGE=SUBNET (multicast on the pair's
subnet), and Fast DDS is held to UDPv4: its shared-memory transport would otherwise carry the
samples between processes of one machine whatever their network namespace."""
import os
import subprocess


def unavailable():
    """Why two namespaces cannot be made here (None: they can)."""
    if os.geteuid() != 0:
        return "needs root (ip netns)"
    try:
        subprocess.run(["ip", "netns", "list"], check=True, capture_output=True)
    except (OSError, subprocess.CalledProcessError) as e:
        return f"`ip netns` does not work here: {e}"
    return None


class TwoHosts:
    """Namespaces `<prefix>_a` and `<prefix>_b`, removed on exit."""

    def __init__(self, prefix=None):
        k = os.getpid() % 250 + 1
        self.prefix = prefix or f"skin{os.getpid()}"
        self.names = {"a": f"{self.prefix}_a", "b": f"{self.prefix}_b"}
        self.addresses = {"a": f"10.213.{k}.1", "b": f"10.213.{k}.2"}

    def __enter__(self):
        ip = lambda *args: subprocess.run(["ip", *args], check=True, capture_output=True)  # noqa: E731
        try:
            for side, ns in self.names.items():
                ip("netns", "add", ns)
            ip("link", "add", f"{self.prefix}a", "type", "veth", "peer", "name", f"{self.prefix}b")
            for side, ns in self.names.items():
                dev = f"{self.prefix}{side}"
                ip("link", "set", dev, "netns", ns)
                ip("-n", ns, "addr", "add", f"{self.addresses[side]}/24", "dev", dev)
                ip("-n", ns, "link", "set", dev, "up", "multicast", "on")
                ip("-n", ns, "link", "set", "lo", "up")
                # Multicast (DDS discovery) leaves through the veth.
                ip("-n", ns, "route", "add", "224.0.0.0/4", "dev", dev)
        except subprocess.CalledProcessError as e:
            self.__exit__(None, None, None)
            raise RuntimeError(f"setting up the namespaces failed: {e.stderr.decode().strip()}") from e
        return self

    def __exit__(self, *exc):
        for ns in self.names.values():
            subprocess.run(["ip", "netns", "del", ns], capture_output=True)

    def command(self, side, argv):
        """`argv` run in namespace `side` ("a" or "b")."""
        return ["ip", "netns", "exec", self.names[side], *map(str, argv)]

    @staticmethod
    def env(base=None):
        """The environment of a node on one of the two hosts."""
        env = dict(base or os.environ)
        env["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "SUBNET"
        env["FASTDDS_BUILTIN_TRANSPORTS"] = "UDPv4"
        return env
