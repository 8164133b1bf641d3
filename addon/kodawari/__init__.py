# Kodawari: procedural creature motion artists can steer.
# register()/unregister() only delegate; registration.py holds the order.
bl_info = {
    "name": "Kodawari",
    "author": "Kodawari developers",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "View3D > Sidebar > Kodawari; Object > Animation > Kodawari; Pose > Kodawari; "
    "Properties > Modifiers (Fish Swim), Object Data (Hair), Object (Gait)",
    "description": "Fish that swim by bending their mesh, view-dependent hair, quadruped gaits",
    # The repository has no public web home yet: these .example addresses (the reserved
    # domain of its commit identity) mark the two places to change when it gets one.
    "doc_url": "https://h-seed-fa26bf0c.example/kodawari#readme",
    "tracker_url": "https://h-seed-fa26bf0c.example/kodawari/issues",
    "category": "Animation",
}


def bake_all(save=True, exit_on_failure=None):
    """Bake every creature in the open .blend and save it, for render farms (see farm.py):
    blender -b shot.blend --python-expr 'import kodawari; kodawari.bake_all()'"""
    from . import farm

    return farm.bake_all(save=save, exit_on_failure=exit_on_failure)


def register():
    from . import registration

    registration.register()


def unregister():
    from . import registration

    registration.unregister()
