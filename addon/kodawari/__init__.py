# Kodawari: procedural creature motion artists can steer.
# register()/unregister() only delegate; registration.py holds the order.
bl_info = {
    "name": "Kodawari",
    "author": "Kodawari developers",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "Properties > Modifiers (Fish Swim), Object Data (Hair, Gait)",
    "description": "Fish that swim by bending their mesh, view-dependent hair, quadruped gaits",
    "category": "Animation",
}


def register():
    from . import registration

    registration.register()


def unregister():
    from . import registration

    registration.unregister()
