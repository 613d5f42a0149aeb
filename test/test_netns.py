"""The graph across hosts, as ROS 2 over DDS spreads it over a skin PC, a robot PC and an operator
PC: mujoco_sim (lockstep) in one network namespace, task_controller in another, joined by a veth
pair (scripts/netns.py: discovery range SUBNET, Fast DDS on UDPv4 only, so nothing passes through
shared memory). The lockstep loop only advances when the controller's commands come back, so
1 s of intentional_contact (500 periods) closing is the loop closing across the link.
Skips without root or `ip netns`."""
import subprocess
import sys

import pytest

from conftest import TOP, binary

sys.path.insert(0, str(TOP / "scripts"))
from netns import TwoHosts, unavailable  # noqa: E402


def test_the_loop_closes_across_two_network_namespaces(spawn):
    why = unavailable()
    if why:
        pytest.skip(why)
    with TwoHosts() as hosts:
        env = hosts.env()
        spawn(*hosts.command("b", [binary("task_controller"), "--setup", TOP / "config/controller/planar7.yaml",
                                   "--ros-args", "-p", "trigger:=inputs", "-p", "supervisor:=internal",
                                   "-p", "control_rate_hz:=500.0"]), env=env)
        sim = subprocess.run(hosts.command("a", [binary("mujoco_sim"), "--scene", "intentional_contact", "--lockstep",
                                                 "--duration", "1"]),
                             env=env, capture_output=True, text=True, timeout=120)
        out = sim.stdout + sim.stderr
        assert sim.returncode == 0 and "after 500 periods" in out, out
