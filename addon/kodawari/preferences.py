"""Add-on preferences: says whether the compiled core loaded, and why not."""

import bpy
from bpy.app.translations import pgettext_tip as tip_

from . import native


def addon_package():
    # "kodawari" as a legacy add-on, "bl_ext.<repo>.kodawari" as an extension.
    return __package__


class KodawariPreferences(bpy.types.AddonPreferences):
    bl_idname = __package__

    hair_cache_megabytes: bpy.props.IntProperty(
        name="Hair Cache Budget",
        default=256,
        min=16,
        soft_max=8192,
        subtype="NONE",
        description="Memory (MB) the live hair frame cache of each armature may use; beyond it only "
        "checkpoints are kept and scrubbing back re-simulates from the nearest one",
    )

    def draw(self, context):
        layout = self.layout
        layout.prop(self, "hair_cache_megabytes")
        if native.available():
            mod = native.module()
            layout.label(
                text=f"Compiled core loaded: kodawari_native {mod.__version__}", icon="CHECKMARK"
            )
        else:
            box = layout.box()
            box.alert = True
            box.label(
                text="Kodawari's compiled core did not load; its tools are disabled.", icon="ERROR"
            )
            for line in _wrap(native.error() or "", 90):
                box.label(text=line)


def _wrap(text, width):
    words, line, lines = text.split(), "", []
    for word in words:
        if line and len(line) + 1 + len(word) > width:
            lines.append(line)
            line = word
        else:
            line = f"{line} {word}".strip()
    if line:
        lines.append(line)
    return lines


class KODAWARI_OT_native_report(bpy.types.Operator):
    """Show why Kodawari's compiled core did not load"""

    bl_idname = "kodawari.native_report"
    bl_label = "Kodawari: Core Not Loaded"
    bl_options = {"INTERNAL"}

    def execute(self, context):
        self.report({"ERROR"}, native.error() or tip_("Kodawari's compiled core did not load"))
        return {"CANCELLED"}
