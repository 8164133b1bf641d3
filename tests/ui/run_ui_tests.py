"""Tests that need Blender's real window: the modal bakes, driven by simulated key
presses. Run by tools/run_tests.sh as
    xvfb-run -a blender --factory-startup -noaudio --enable-event-simulate \
        --python tools/blender_install_addon.py --python tests/ui/run_ui_tests.py
(--enable-event-simulate makes Window.event_simulate available and ignores real input).

Each scenario is a generator that sets a scene up, invokes a bake as a user would
(INVOKE_DEFAULT in the 3D view), yields the seconds to wait, and asserts. The script
writes a JUnit report and exits non-zero when a scenario fails."""

import os
import sys
import tempfile
import time
import traceback
import xml.etree.ElementTree as ET

import bpy

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path[:0] = [os.path.join(ROOT, "blend_samples"), os.path.join(ROOT, "tests", "blender")]
REPORT = os.environ.get("KODAWARI_UI_REPORT", os.path.join(tempfile.gettempdir(), "kodawari-ui.xml"))
TIMEOUT = 60.0


def window():
    return bpy.context.window_manager.windows[0]


def view3d_context():
    """The context a click in the 3D view has (timers run with no window of their own)."""
    win = window()
    area = next(a for a in win.screen.areas if a.type == "VIEW_3D")
    region = next(r for r in area.regions if r.type == "WINDOW")
    return bpy.context.temp_override(window=win, screen=win.screen, area=area, region=region)


def invoke(operator, **kwargs):
    """Calls an operator as a click would: invoke(), which starts the modal bake."""
    module, name = operator.split(".")
    result = getattr(getattr(bpy.ops, module), name)("INVOKE_DEFAULT", **kwargs)
    assert result == {"RUNNING_MODAL"}, f"{operator} did not start a modal bake: {result}"


def press_escape():
    win = window()
    win.event_simulate(type="ESC", value="PRESS")
    win.event_simulate(type="ESC", value="RELEASE")


def wait_until(condition, what):
    start = time.monotonic()
    while not condition():
        assert time.monotonic() - start < TIMEOUT, f"timed out waiting for {what}"
        yield 0.1


def fresh_file():
    """The scene of the empty file the driver opened before this scenario."""
    return bpy.context.scene


def activate(obj):
    for other in bpy.context.view_layer.objects:
        other.select_set(False)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)


# --- fish ----------------------------------------------------------------------
def fish_scene():
    import fish_shapes

    scene = fresh_file()
    obj = fish_shapes.build_fish("tuna", head_axis="POS_X")
    activate(obj)
    assert bpy.ops.kodawari.swim_add(head_axis="POS_X") == {"FINISHED"}
    return scene, obj


def fish_state(obj, cache):
    keys = obj.data.shape_keys
    return ([m.type for m in obj.modifiers], [k.name for k in keys.key_blocks] if keys else [],
            obj.kodawari_swim.enabled, os.path.exists(cache), os.path.exists(cache + ".part"),
            bpy.context.scene.frame_current)


def fish_bake_escape():
    scene, obj = fish_scene()
    cache = os.path.join(tempfile.mkdtemp(), "tuna.pc2")
    before = fish_state(obj, cache)
    invoke("kodawari.swim_bake", frame_start=1, frame_end=2000, target="MESH_CACHE", filepath=cache)
    yield 0.05
    press_escape()
    yield 0.5
    assert fish_state(obj, cache) == before, (before, fish_state(obj, cache))


def fish_bake_completes():
    scene, obj = fish_scene()
    cache = os.path.join(tempfile.mkdtemp(), "tuna.pc2")
    invoke("kodawari.swim_bake", frame_start=1, frame_end=12, target="MESH_CACHE", filepath=cache)
    yield from wait_until(lambda: any(m.type == "MESH_CACHE" for m in obj.modifiers), "the Mesh Cache modifier")
    assert os.path.getsize(cache) == 32 + 12 * len(obj.data.vertices) * 12


# --- gait ----------------------------------------------------------------------
def gait_scene():
    import gait_samples as samples

    scene = fresh_file()
    rig, _ = samples.build_horse(scene)
    activate(rig)
    assert bpy.ops.kodawari.gait_setup() == {"FINISHED"}
    samples.key_speed(rig, ((1, 2.0), (2000, 12.0)))
    return scene, rig


def gait_state(rig):
    from gait_scene import fcurve_snapshot

    return fcurve_snapshot(rig), sorted(k for k in rig.keys() if k.startswith("kodawari_"))


def gait_bake_escape():
    scene, rig = gait_scene()
    before = gait_state(rig)
    invoke("kodawari.gait_bake", frame_start=1, frame_end=20000)
    yield 0.03
    press_escape()
    yield 0.5
    assert gait_state(rig) == before, "Esc left gait channels behind"


def gait_bake_completes():
    scene, rig = gait_scene()
    invoke("kodawari.gait_bake", frame_start=1, frame_end=48)
    yield from wait_until(lambda: "kodawari_contact_LF" in rig.keys(), "the contact channels")
    yield from wait_until(lambda: any('kodawari_contact_RH' in path for path, _ in gait_state(rig)[0]),
                          "the last contact F-curve")


# --- hair ----------------------------------------------------------------------
def hair_scene():
    from hair_rig import add_camera, make_rig, select_only

    scene = fresh_file()
    rig = make_rig(scene)
    add_camera(scene, "Front", (0.0, -3.0, 1.7))
    select_only(rig, {"Ahoge.00"})
    assert bpy.ops.kodawari.rod_add() == {"FINISHED"}
    bpy.ops.object.mode_set(mode="OBJECT")
    return scene, rig


def hair_state(rig):
    anim = rig.animation_data
    return (anim.action.name if anim and anim.action else None), rig.kodawari_hair.enabled, scene_frame()


def scene_frame():
    return bpy.context.scene.frame_current


def hair_bake_escape():
    scene, rig = hair_scene()
    before = hair_state(rig)
    invoke("kodawari.rod_bake", frame_start=1, frame_end=5000)
    yield 0.05
    press_escape()
    yield 0.5
    assert hair_state(rig) == before, (before, hair_state(rig))


def hair_bake_completes():
    scene, rig = hair_scene()
    invoke("kodawari.rod_bake", frame_start=1, frame_end=24)
    yield from wait_until(lambda: not rig.kodawari_hair.enabled, "the bake to finish")
    assert rig.animation_data and rig.animation_data.action, "no action after the bake"


SCENARIOS = [fish_bake_escape, fish_bake_completes, gait_bake_escape, gait_bake_completes,
             hair_bake_escape, hair_bake_completes]
results = []
state = {"index": -1, "runner": None, "start": 0.0}


def finish():
    suite = ET.Element("testsuite", name="ui", tests=str(len(results)),
                       failures=str(sum(1 for r in results if r[1])))
    for name, failure, seconds in results:
        case = ET.SubElement(suite, "testcase", classname="tests.ui", name=name, time=f"{seconds:.2f}")
        if failure:
            ET.SubElement(case, "failure", message=failure.splitlines()[-1]).text = failure
    ET.ElementTree(suite).write(REPORT)
    failed = sum(1 for r in results if r[1])
    for name, failure, _seconds in results:
        print(f"{'FAILED' if failure else 'passed'} {name} ({_seconds:.1f} s)" + (f"\n{failure}" if failure else ""))
    print(f"{len(results) - failed} passed, {failed} failed")
    sys.stdout.flush()
    os._exit(1 if failed else 0)


def drive():
    """Timer: advances the current scenario; starts the next when it ends."""
    try:
        if state["runner"] is None:
            state["index"] += 1
            if state["index"] >= len(SCENARIOS):
                finish()
            # A new empty file per scenario, opened outside any context override: it replaces the screen.
            bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
            state["runner"], state["start"] = SCENARIOS[state["index"]](), time.monotonic()
            return 0.3
        with view3d_context():
            return next(state["runner"])
    except StopIteration:
        failure = None
    except Exception:  # noqa: BLE001 - every failure is recorded, the run goes on
        failure = traceback.format_exc()
    results.append((SCENARIOS[state["index"]].__name__, failure, time.monotonic() - state["start"]))
    state["runner"] = None
    return 0.2


bpy.app.timers.register(drive, first_interval=1.0, persistent=True)
