"""The add-on's entry in Preferences: Documentation and Report a Bug buttons, a location
line that says where the tools really are, and a maintainer with a contact."""

import os
import tomllib

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def test_bl_info_has_documentation_and_bug_links(addon):
    info = addon.bl_info
    assert info["doc_url"].startswith("https://") and info["tracker_url"].startswith("https://")
    location = info["location"]
    assert "Sidebar > Kodawari" in location and "Object > Animation" in location
    assert "Object (Gait)" in location, "the gait panel is in Object properties, not Object Data"
    assert "Object Data (Hair)" in location and "Modifiers (Fish Swim)" in location


def test_manifest_names_a_contact_and_a_website(addon):
    with open(os.path.join(ROOT, "addon", "kodawari", "blender_manifest.toml"), "rb") as file:
        manifest = tomllib.load(file)
    assert "<" in manifest["maintainer"] and "@" in manifest["maintainer"], (
        "maintainer has a contact address"
    )
    assert manifest["website"] == addon.bl_info["doc_url"]
