"""Runtime state of gait bakes: the last bake's solver output per armature, kept so the
report and tests can compare what was solved with what the Action holds. Rebuilt
(emptied) when a file opens: the Action in the file is the truth. Keyed by the object's
as_pointer(), which a rename keeps (CONTRIBUTING.md, "Runtime caches")."""

_last = {}


def remember(obj, job):
    _last[obj.as_pointer()] = {
        "frames": job.frames,
        "fps": job.fps,
        "result": job.result,
        "rig": job.rig,
        "chains": job.chains,
    }


def last_bake(obj):
    return _last.get(obj.as_pointer())


def forget():
    """A file opened: drop every remembered bake (the Action in the file is the truth)."""
    _last.clear()
