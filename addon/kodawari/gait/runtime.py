"""Runtime state of gait bakes: the last bake's solver output per armature, kept so the
report and tests can compare what was solved with what the Action holds. Rebuilt
(emptied) when a file opens: the Action in the file is the truth."""

import bpy
from bpy.app.handlers import persistent

_last = {}


def remember(obj, job):
    _last[obj.name] = {"frames": job.frames, "fps": job.fps, "result": job.result, "rig": job.rig,
                       "chains": job.chains}


def last_bake(obj):
    return _last.get(obj.name)


@persistent
def on_load_post(_dummy=None):
    _last.clear()
