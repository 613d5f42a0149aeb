"""The launch files name only things that exist. No launch runtime is installed here, so each file
is parsed (ast): every `executable=` of a skin_control Node must be a skin_control binary
(skin_control/src/bin/<name>.rs), and every file the launch files name through `share(...)` or a
path default (config/..., urdf/...) must exist in the package and be installed to its share
directory on a colcon build (skin_control/Cargo.toml's `install_to_share`)."""
import ast
import tomllib

import pytest

from conftest import TOP

LAUNCH = sorted((TOP / "launch").glob("*.launch.py"))
BINARIES = {p.stem for p in (TOP / "skin_control" / "src" / "bin").glob("*.rs")}


def calls(tree, name):
    return [n for n in ast.walk(tree) if isinstance(n, ast.Call)
            and getattr(n.func, "id", getattr(n.func, "attr", None)) == name]


def const(node):
    return node.value if isinstance(node, ast.Constant) and isinstance(node.value, str) else None


@pytest.mark.parametrize("path", LAUNCH, ids=lambda p: p.name)
def test_launch_file_names_existing_things(path):
    tree = ast.parse(path.read_text(), filename=str(path))
    assert any(isinstance(n, ast.FunctionDef) and n.name == "generate_launch_description" for n in tree.body)
    nodes = 0
    for call in calls(tree, "Node"):
        kw = {k.arg: k.value for k in call.keywords}
        pkg = kw.get("package")
        if isinstance(pkg, ast.Name) and pkg.id == "PKG" or const(pkg) == "skin_control":
            exe = const(kw["executable"])
            assert exe in BINARIES, f"{path.name}: executable {exe} is not a skin_control binary {sorted(BINARIES)}"
            nodes += 1
    assert nodes >= 3, f"{path.name}: expected the skin_control nodes"
    files = [["/".join(const(a) for a in c.args)] for c in calls(tree, "share") if all(const(a) for a in c.args)]
    files += [[const(k.value)] for c in calls(tree, "DeclareLaunchArgument") for k in c.keywords
              if k.arg == "default_value" and const(k.value) and const(k.value).startswith(("config/", "urdf/"))]
    assert files, f"{path.name}: names no files"
    for (f,) in files:
        assert (TOP / f).is_file(), f"{path.name}: {f} does not exist"


def test_the_colcon_install_puts_what_the_launch_files_name_into_share():
    # cargo-ament-build copies each entry to share/<package>/<its last path component>.
    manifest = tomllib.loads((TOP / "skin_control" / "Cargo.toml").read_text())
    entries = manifest["package"]["metadata"]["ros"]["install_to_share"]
    installed = {(TOP / "skin_control" / e).resolve().relative_to(TOP).as_posix(): e.rsplit("/", 1)[-1] for e in entries}
    assert installed.get("launch") == "launch", "the launch files themselves (ros2 launch skin_control ...)"
    for path in LAUNCH:
        tree = ast.parse(path.read_text(), filename=str(path))
        for c in calls(tree, "share"):
            parts = [const(a) for a in c.args]
            if parts and parts[0]:
                assert installed.get(parts[0]) == parts[0], f"{path.name}: share({parts[0]!r}, ...) is not installed to share"


def test_sim_launch_covers_the_graph():
    text = (TOP / "launch" / "sim.launch.py").read_text()
    for exe in ("mujoco_sim", "task_controller", "priority_supervisor", "skin_aggregator", "robot_state_publisher"):
        assert f'executable="{exe}"' in text
    assert (TOP / "config" / "skin.rviz").read_text().count("/skin/markers") == 1


def test_the_launch_files_start_the_watchdog_and_activate_only_the_simulation():
    for name, autostart in (("tomm.launch.py", "false"), ("sim.launch.py", "true")):
        tree = ast.parse((TOP / "launch" / name).read_text())
        exes = [const(k.value) for c in calls(tree, "Node") for k in c.keywords if k.arg == "executable"]
        assert "skin_watchdog" in exes and "task_controller" in exes, (name, exes)
        defaults = {const(c.args[0]): const(k.value) for c in calls(tree, "DeclareLaunchArgument")
                    for k in c.keywords if k.arg == "default_value"}
        assert defaults.get("autostart") == autostart, (name, defaults)
