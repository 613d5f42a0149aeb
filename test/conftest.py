"""Shared fixtures of the topic-level integration tests: where the built binaries are, and
processes that are always stopped when a test ends."""
import os
import subprocess
import time
from pathlib import Path

import pytest

TOP = Path(__file__).resolve().parent.parent

# A DDS domain of this test session's own (inherited by every node it starts): graphs of other
# sessions on the same machine (a demo, a second checkout's tests) must not cross-talk. Set
# whatever the shell had (.deps/env.sh sets 57 for every shell, so a default would never apply).
os.environ["ROS_DOMAIN_ID"] = str(1 + os.getpid() % 100)


def target_dir() -> Path:
    """Cargo's output directory of the build under test (`make test` sets SKIN_TARGET_DIR)."""
    return Path(os.environ.get("SKIN_TARGET_DIR", TOP / "target" / "debug"))


def binary(name: str) -> Path:
    """Path of a built binary or example; fails the test with a hint when it is missing."""
    for cand in (target_dir() / name, target_dir() / "examples" / name):
        if cand.is_file():
            return cand
    pytest.fail(f"{name} is not built in {target_dir()}: run `make build` first")


@pytest.fixture
def spawn():
    """Start processes for one test; every one of them is terminated (then killed) at the end."""
    procs = []

    def _spawn(*args, **kw):
        p = subprocess.Popen([str(a) for a in args], stdout=subprocess.PIPE,
                             stderr=subprocess.STDOUT, text=True, **kw)
        procs.append(p)
        return p

    yield _spawn
    for p in procs:
        if p.poll() is None:
            p.terminate()
    for p in procs:
        try:
            p.wait(timeout=5)
        except subprocess.TimeoutExpired:
            p.kill()
            p.wait()


@pytest.fixture
def rclpy_node(request):
    """An rclpy node (the outside peer) with its own context, destroyed after the test."""
    import rclpy
    from rclpy.context import Context

    ctx = Context()
    rclpy.init(context=ctx)
    node = rclpy.create_node(f"peer_{request.node.name[:40]}".replace("[", "_").replace("]", "_")
                             .replace("-", "_"), context=ctx)
    yield node
    node.destroy_node()
    rclpy.shutdown(context=ctx)


def spin_until(node, predicate, timeout_s: float, what):
    """Spin `node` until `predicate()` holds; fail naming `what` (a string, or a function giving
    one at the time of failure) after `timeout_s` (a bound on a wait for an event, not a timing
    assertion)."""
    import rclpy
    from rclpy.executors import SingleThreadedExecutor

    ex = SingleThreadedExecutor(context=node.context)
    ex.add_node(node)
    deadline = time.monotonic() + timeout_s
    try:
        while not predicate():
            if time.monotonic() > deadline:
                pytest.fail(f"timed out after {timeout_s} s waiting for "
                            f"{what() if callable(what) else what}")
            ex.spin_once(timeout_sec=0.05)
    finally:
        ex.remove_node(node)


@pytest.fixture(scope="module")
def store():
    """rosbags' typestore: ROS 2 Jazzy types plus skin_msgs from its .msg files."""
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    ts = get_typestore(Stores.ROS2_JAZZY)
    types = {}
    for f in sorted((TOP / "skin_msgs" / "msg").glob("*.msg")):
        types.update(get_types_from_msg(f.read_text(), f"skin_msgs/msg/{f.stem}"))
    ts.register(types)
    return ts


def plain(v):
    """A message as nested dicts and lists of Python numbers and strings, for exact comparison
    (a NaN as the string "NaN": NaN equals nothing, not even itself)."""
    import math

    import numpy as np

    if hasattr(v, "__dataclass_fields__"):
        return {k: plain(getattr(v, k)) for k in v.__dataclass_fields__ if k != "__msgtype__"}
    if isinstance(v, np.ndarray):
        return plain(v.tolist()) if v.dtype.kind == "f" and np.isnan(v).any() else v.tolist()
    if isinstance(v, (list, tuple)):
        return [plain(x) for x in v]
    if isinstance(v, float) and math.isnan(v):
        return "NaN"
    return v


def call_service(node, srv_type, name, request, timeout=30.0):
    """Calls the service `name` from the rclpy `node` and returns the reply (waits for the service
    and the reply with `spin_until`)."""
    client = node.create_client(srv_type, name)
    spin_until(node, client.service_is_ready, timeout, f"service {name}")
    future = client.call_async(request)
    spin_until(node, future.done, timeout, f"a reply from {name}")
    return future.result()


def set_parameter(node, target, name, value):
    """Sets parameter `name` of the node `target` (e.g. `/task_controller`) through its standard
    set_parameters service; returns the SetParametersResult."""
    from rcl_interfaces.msg import Parameter
    from rcl_interfaces.srv import SetParameters
    from rclpy.parameter import Parameter as P

    req = SetParameters.Request()
    req.parameters = [Parameter(name=name, value=P(name, value=value).get_parameter_value())]
    return call_service(node, SetParameters, f"{target}/set_parameters", req).results[0]


def cell_array(entries, stamp=None):
    """A skin_msgs/SkinCellArray of `(cell_id, force[3], proximity)` cells (the arrays, cell k at
    index k), stamped `stamp` (a builtin_interfaces/Time) if given."""
    from skin_msgs.msg import SkinCellArray

    msg = SkinCellArray()
    msg.cell_id = [cell_id for cell_id, _, _ in entries]
    msg.force = [float(v) for _, force, _ in entries for v in force]
    msg.proximity = [float(prox) for _, _, prox in entries]
    if stamp is not None:
        msg.header.stamp = stamp
    return msg


def ros2_or_skip():
    """The `ros2` command line with the launch system, or skip the test saying how to get it."""
    import shutil

    exe = shutil.which("ros2")
    probe = exe and subprocess.run([exe, "launch", "--help"], capture_output=True).returncode == 0
    if not probe:
        pytest.skip("needs the ROS 2 Jazzy command line (`ros2 launch`): on a robot source "
                    "/opt/ros/jazzy/setup.bash; without it scripts/bootstrap installs them from "
                    "third_party/ros2-jazzy-python (re-run it)")
    return exe


@pytest.fixture(scope="session")
def ament_prefix(tmp_path_factory):
    """skin_control and skin_sim_ros installed as `colcon build` installs them (cargo-ament-build's
    layout: the ament index markers, share/<pkg>/{package.xml, launch, ...}, lib/<pkg>/<bins>),
    copied from the repository, the binaries linked to the build under test; returns the
    environment that puts the prefix first on AMENT_PREFIX_PATH, for `ros2 launch <pkg> ...`."""
    import shutil

    prefix = tmp_path_factory.mktemp("install")
    index = prefix / "share" / "ament_index" / "resource_index" / "packages"
    index.mkdir(parents=True)
    packages = {"skin_control": (["launch", "config", "urdf"], ["task_controller", "skin_watchdog", "priority_supervisor", "skin_aggregator"]),
                "skin_sim_ros": (["skin_sim_ros/launch"], ["mujoco_sim"])}
    for pkg, (dirs, exes) in packages.items():
        (index / pkg).write_text("")
        share = prefix / "share" / pkg
        share.mkdir()
        (share / "package.xml").symlink_to(TOP / pkg / "package.xml")
        for d in dirs:
            shutil.copytree(TOP / d, share / d.rsplit("/", 1)[-1])
        lib = prefix / "lib" / pkg
        lib.mkdir(parents=True)
        for exe in exes:
            (lib / exe).symlink_to(binary(exe))
    env = dict(os.environ)
    env["AMENT_PREFIX_PATH"] = f"{prefix}:{env.get('AMENT_PREFIX_PATH', '')}"
    return env
