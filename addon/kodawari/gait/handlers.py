"""Persistent application handlers of the gaits: forget the last bakes when a file opens."""

from bpy.app.handlers import persistent

from . import runtime


@persistent
def on_load(_dummy=None, *_args):
    runtime.forget()
