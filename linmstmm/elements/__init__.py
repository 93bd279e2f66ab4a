"""Element transfer matrices, 12x12, modal coordinates, inertial frame.

State vector at a point: ``Z = [X, Y, Z, Θx, Θy, Θz, Mx, My, Mz, Qx, Qy, Qz]``
(displacement, rotation, internal moment, internal force). The internal
force/moment is what the element upstream (towards the tips) exerts on the
element downstream (towards the root). Every function takes an array of
circular frequencies ``omega`` (rad/s, shape ``(n,)``) and returns a stack of
shape ``(n, 12, 12)``: ``Z_out = U @ Z_in``.

One module per element kind: :mod:`.spring`, :mod:`.rigid`, :mod:`.beam`;
:mod:`.frames` holds the small geometric helpers they share.
"""
