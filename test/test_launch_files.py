"""The launch files name only things that exist, also where no `ros2` command line is installed
(test_launch_sim.py runs them). Each file is parsed (ast): every `executable=` of a Node of our
packages must be a binary of that package (skin_control/src/bin, skin_sim_ros/src/bin), every file
named through `share_file(...)` must exist in skin_control and be installed to its share directory
on a colcon build (the packages' `install_to_share`)."""
import ast
import tomllib

import pytest
import yaml

from conftest import TOP

LAUNCH = sorted([*(TOP / "launch").glob("*.py"), *(TOP / "skin_sim_ros" / "launch").glob("*.py")])
PACKAGES = {"PKG": "skin_control", "SIM_PKG": "skin_sim_ros"}
BINARIES = {pkg: {p.stem for p in (TOP / pkg / "src" / "bin").glob("*.rs")} for pkg in PACKAGES.values()}


def calls(tree, name):
    return [n for n in ast.walk(tree) if isinstance(n, ast.Call)
            and getattr(n.func, "id", getattr(n.func, "attr", None)) == name]


def const(node):
    return node.value if isinstance(node, ast.Constant) and isinstance(node.value, str) else None


@pytest.mark.parametrize("path", LAUNCH, ids=lambda p: p.name)
def test_launch_file_names_existing_things(path):
    tree = ast.parse(path.read_text(), filename=str(path))
    if path.name.endswith(".launch.py"):
        assert any(isinstance(n, ast.FunctionDef) and n.name == "generate_launch_description" for n in tree.body)
    for call in calls(tree, "Node"):
        kw = {k.arg: k.value for k in call.keywords}
        pkg = kw.get("package")
        pkg = PACKAGES.get(pkg.id) if isinstance(pkg, ast.Name) else const(pkg)
        if pkg in BINARIES:
            exe = const(kw["executable"])
            assert exe in BINARIES[pkg], f"{path.name}: executable {exe} is not a {pkg} binary {sorted(BINARIES[pkg])}"
    for c in calls(tree, "share_file"):
        parts = [const(a) for a in c.args]
        if all(parts):
            assert (TOP.joinpath(*parts)).is_file(), f"{path.name}: {'/'.join(parts)} does not exist"


def test_the_colcon_install_puts_what_the_launch_files_name_into_share():
    # cargo-ament-build copies each entry to share/<package>/<its last path component>.
    manifest = tomllib.loads((TOP / "skin_control" / "Cargo.toml").read_text())
    entries = manifest["package"]["metadata"]["ros"]["install_to_share"]
    installed = {(TOP / "skin_control" / e).resolve().relative_to(TOP).as_posix(): e.rsplit("/", 1)[-1] for e in entries}
    assert installed.get("launch") == "launch", "the launch files themselves (ros2 launch skin_control ...)"
    sim = tomllib.loads((TOP / "skin_sim_ros" / "Cargo.toml").read_text())["package"]["metadata"]["ros"]
    assert "launch" in sim["install_to_share"], "ros2 launch skin_sim_ros sim.launch.py"
    for path in LAUNCH:
        tree = ast.parse(path.read_text(), filename=str(path))
        for c in calls(tree, "share_file"):
            parts = [const(a) for a in c.args]
            if parts and parts[0]:
                assert installed.get(parts[0]) == parts[0], f"{path.name}: share_file({parts[0]!r}, ...) is not installed to share"


def test_the_rviz_config_shows_the_markers():
    rviz = yaml.safe_load((TOP / "config" / "skin.rviz").read_text())
    topics = [d.get("Topic", {}).get("Value") for d in rviz["Visualization Manager"]["Displays"]]
    assert "/skin/markers" in topics


def test_the_launch_files_start_the_watchdog_and_activate_only_the_simulation():
    shared = ast.parse((TOP / "launch" / "skin_control_launch.py").read_text())
    exes = [const(k.value) for c in calls(shared, "Node") for k in c.keywords if k.arg == "executable"]
    assert "skin_watchdog" in exes and "task_controller" in exes, exes
    sim = ast.parse((TOP / "skin_sim_ros" / "launch" / "sim.launch.py").read_text())
    defaults = {const(c.args[0]): const(k.value) for c in calls(sim, "DeclareLaunchArgument")
                for k in c.keywords if k.arg == "default_value"}
    assert defaults.get("autostart") == "true", defaults
    tomm = ast.parse((TOP / "launch" / "tomm.launch.py").read_text())
    args = {const(t.elts[0]): const(t.elts[1]) for t in ast.walk(tomm)
            if isinstance(t, ast.Tuple) and len(t.elts) == 3 and all(const(e) is not None for e in t.elts[:2])}
    assert args.get("autostart") == "", args  # launch_setup: false for hardware:=real, true for sim
