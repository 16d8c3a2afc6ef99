"""Fracture from the field: bricks glued by breakable Fixed constraints made with Physics ›
Rigid Body › Connect, struck by a dropped ball. The impact breaks what it overloads while it
strikes; what is left holds, and nothing breaks after the impact."""

import math

import bpy

import field

FRAMES = 72
BRICKS = 8
SIZE = 0.4
#: The ball's drop (m) from its lowest point to the bridge's top, and the frame it lands on.
DROP = 1.7
IMPACT_FRAME = 1 + math.sqrt(2 * DROP / 9.81) * 24


def bridge(threshold=2.0, ball_mass=10.0):
    """A bridge of ``BRICKS`` default-mass cubes between two passive posts, top at z = 2 m,
    joined in a chain (posts included) by Connect's Fixed constraints, Breakable at
    ``threshold``; a ball of ``ball_mass`` kg dropped onto its middle from ``DROP`` above."""
    scene = field.startup(FRAMES)
    field.ground()
    span = BRICKS * SIZE
    posts = []
    for side, name in ((-1, "PostL"), (1, "PostR")):
        post = field.add("cube", name, size=1.0, location=(side * (span + SIZE) / 2, 0.0, 1.0))
        post.scale = (SIZE, SIZE, 2.0)
        bpy.context.view_layer.update()
        posts.append(field.rigid(post, "PASSIVE"))
    bricks = []
    for i in range(BRICKS):
        location = (-span / 2 + SIZE * (i + 0.5), 0.0, 2.0 - SIZE / 2)
        bricks.append(field.rigid(field.add("cube", f"Brick{i}", size=SIZE, location=location)))
    # Select the posts and bricks, the left post active: Connect, Fixed, Chain by Distance.
    for other in bpy.context.view_layer.objects:
        other.select_set(False)
    for obj in posts + bricks:
        obj.select_set(True)
    bpy.context.view_layer.objects.active = posts[0]
    bpy.ops.rigidbody.connect(con_type="FIXED", pivot_type="CENTER", connection_pattern="CHAIN_DISTANCE")
    glue = [obj.rigid_body_constraint for obj in bpy.data.objects if obj.rigid_body_constraint]
    assert len(glue) == BRICKS + 1
    for constraint in glue:
        constraint.use_breaking = True
        constraint.breaking_threshold = threshold
    ball = field.rigid(field.add("uv_sphere", "Ball", radius=0.3, location=(0.05, 0.0, 2.0 + DROP + 0.3)))
    ball.rigid_body.mass = ball_mass
    return scene, bricks, glue


def first_separations(scene, glue):
    """Per constraint, the first frame at which its two objects moved more than 1 cm relative
    to each other (what a viewer sees of a break), or None."""
    pairs = [(c.object1, c.object2) for c in glue]

    def relative(frame):
        scene.frame_set(frame)
        return [a.matrix_world.inverted() @ b.matrix_world.translation for a, b in pairs]

    start = relative(1)
    first = [None] * len(pairs)
    for frame in range(2, FRAMES + 1):
        for k, (before, now) in enumerate(zip(start, relative(frame), strict=True)):
            if first[k] is None and (now - before).length > 0.01:
                first[k] = frame
    return first


def test_a_bridge_struck_by_a_ball_breaks_at_the_impact_and_the_rest_holds():
    from impulse_bake import bake

    scene, bricks, glue = bridge()
    bake.bake_scene(scene)
    first = first_separations(scene, glue)
    broken = [f for f in first if f is not None]
    print(f"impact at frame {IMPACT_FRAME:.1f}; constraints parting at frames {first}")
    scene.frame_set(FRAMES)
    heights = [brick.matrix_world.translation.z for brick in bricks]
    middle, sides = heights[3:5], heights[:3] + heights[5:]
    assert all(z < 0.5 for z in middle), f"the struck bricks fell: {heights}"
    assert broken, "the impact breaks the bridge"
    assert all(IMPACT_FRAME - 1 <= f <= IMPACT_FRAME + 5 for f in broken), (
        f"every break within the impact's frames, none after: {first}"
    )
    assert all(abs(z - (2.0 - SIZE / 2)) < 0.01 for z in sides), f"the rest of the bridge holds: {heights}"
