"""Translations of every Kodawari UI string (labels, tooltips, reports), registered
through bpy.app.translations. Blender looks labels up in the default context ("*"),
operator names in the "Operator" context, so each entry is registered in both.

To see which strings still lack a translation: tools/i18n_missing.py."""

import bpy

from . import ja

LANGUAGES = {"ja_JP": ja.STRINGS}
CONTEXTS = ("*", "Operator")


def dictionary():
    return {
        locale: {(context, msgid): text for msgid, text in strings.items() for context in CONTEXTS}
        for locale, strings in LANGUAGES.items()
    }


def msgids():
    """Every UI string of the registered add-on that needs a translation."""
    from . import drawn, strings

    found = {s.text for s in strings.registered() if s.text.strip()}
    found |= drawn.strings()
    return {text for text in found if any(c.isalpha() for c in text)}


def missing(locale):
    table = LANGUAGES.get(locale, {})
    return sorted(text for text in msgids() if text not in table)


def unused(locale):
    """Entries no UI string asks for any more (renamed or removed): safe to delete."""
    wanted = msgids()
    return sorted(text for text in LANGUAGES.get(locale, {}) if text not in wanted)


def register():
    unregister()
    bpy.app.translations.register(__name__, dictionary())


def unregister():
    try:
        bpy.app.translations.unregister(__name__)
    except (ValueError, RuntimeError):
        pass  # not registered
