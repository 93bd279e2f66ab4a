"""Compiled kernels: det Ū_all(ω) by replaying a :class:`~linmstmm.program.Program`.

Every kernel here is compiled once by numba (``@njit(cache=True)``: the
machine code is kept beside this file, so later processes only load it) and
takes float64/complex128 arrays and integers only. Each mirrors a numpy
counterpart that stays the readable reference and the test oracle:

* :func:`beam_piece` — :func:`linmstmm.elements.beam.beam_transfer`;
* :func:`evaluate` — :meth:`linmstmm.deduction.Deduction.matrix` and
  :meth:`~linmstmm.deduction.Deduction.log_det` with ``stable=True``: the carry
  with Godunov orthonormalisation (:class:`linmstmm.godunov._Orthonormaliser`),
  beams cut into pieces of βL ≤ 4, Ū_all assembled, LU (of what remains once
  its lone columns are expanded along: :func:`_block_log_det`).

Two intrinsics build array views directly in LLVM, where numba's own cost more
than the arithmetic around them: :func:`_view` (a slot's block of the workspace)
and :func:`_unowned` (the replay's arrays without reference counts). Scratch is
allocated once per call of :func:`evaluate`.

Frequencies are evaluated in groups of consecutive entries that take the
same decisions (pieces per beam, orthonormalisations skipped), as one numpy
stack does: a group of two, ω and ω + δω, gives a smooth difference of the
orthonormalised Ū_all (Newton's pencil).

Kept whole: numba invalidates cached machine code when the file that defines
a kernel changes, not when a kernel it calls in another file does (its
documented limit); split across files, an edit to a callee would leave its
callers running the old code from the cache. The cached replay also keeps the
operation codes and block kinds it reads from :mod:`linmstmm.program_record`
(through :mod:`linmstmm.program`), which numba compiles in as constants: after a
change to their values, touch this file (or delete its cache), or the cached
replay reads programs by the old codes.
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit, types
from numba.core import cgutils
from numba.core.imputils import impl_ret_borrowed
from numba.extending import intrinsic
from numba.np.arrayobj import populate_array

from linmstmm._compile_notice import announce_compiles
from linmstmm._lapack import lapack_routine
from linmstmm.program import BEAM, CARRY, COMBINE, GEOMETRIC, JOINT, ORTHO, STATE_BLOCK, TIP

announce_compiles()  # one line on stderr if this run compiles (linmstmm._compile_notice)

#: See linmstmm.deduction: beam pieces, growth between orthonormalisations, far scale.
BEAM_PIECE_BETA_L = 4.0
GROWTH = 1e2
FAR = 1e100
_SERIES_LIMIT4 = 16.0  # |w| below 2**4: Krylov functions by their power series
_SERIES_TERMS = 14
_FACTORIALS = np.array([[1.0 / math.factorial(4 * j + r) for j in range(_SERIES_TERMS)] for r in range(4)])
_XY = np.array([1, 5, 8, 10])
_XZ = np.array([2, 4, 7, 11])
_XZ_SIGNS = np.array([1.0, -1.0, -1.0, 1.0])
_ONES = np.ones(4)
_BENDING_SIGNS = np.outer([1.0, 1.0, -1.0, 1.0], [1.0, 1.0, -1.0, 1.0])


@intrinsic
def _unowned(typingctx, value):
    """``value``, an array or a tuple of arrays and integers, with every array's owner
    dropped: the same data, shape and strides, and no reference counts. numba counts
    references to an array's owner with an atomic operation wherever the array is passed
    to a function or viewed, some thousands of times per evaluation; an array without
    an owner skips them. Only for arrays the caller keeps alive meanwhile, such as the
    arguments of the kernel that calls it."""
    def codegen(context, builder, signature, arguments):
        return _without_owners(context, builder, value, arguments[0])
    return value(value), codegen


def _without_owners(context, builder, kind, value):
    """The LLVM ``value`` of numba type ``kind`` with a null owner (meminfo) in every array."""
    if isinstance(kind, types.Array):
        array = context.make_array(kind)(context, builder, value)
        array.meminfo = cgutils.get_null_value(array.meminfo.type)
        return array._getvalue()
    if isinstance(kind, types.BaseTuple):
        members = [_without_owners(context, builder, member, builder.extract_value(value, i))
                   for i, member in enumerate(kind)]
        return context.make_tuple(builder, kind, members)
    return value


@njit(cache=True)
def _krylov(w, out):
    """Scaled Krylov functions F_0..F_3 of w into ``out`` (4,): see linmstmm.elements.beam.krylov."""
    if abs(w) < _SERIES_LIMIT4:
        for r in range(4):
            total = 0.0 * w
            power = 1.0 + 0.0 * w
            for j in range(_SERIES_TERMS):
                total += _FACTORIALS[r, j] * power
                power *= w
            out[r] = total
    else:
        z = np.sqrt(np.sqrt(w))
        ch, c, sh, s = np.cosh(z), np.cos(z), np.sinh(z), np.sin(z)
        out[0] = (ch + c) / 2
        out[1] = (sh + s) / (2 * z)
        out[2] = (ch - c) / (2 * z * z)
        out[3] = (sh - s) / (2 * z * z * z)


@njit(cache=True)
def _bending(EI, rhoA, L, omega, local, indices, signs, functions):
    """The (v, θ, m, q) bending block of one plane into ``local`` at ``indices``."""
    w = rhoA * omega * omega * L ** 4 / EI
    _krylov(w, functions)
    inverse_L = 1.0 / L
    lengths = (inverse_L ** 3, inverse_L * inverse_L, inverse_L, 1.0, L, L * L, L ** 3)  # L**(j - i)
    stiffness = (1.0 / EI, 1.0, EI)
    for i in range(4):
        for j in range(4):
            value = _BENDING_SIGNS[i, j] * lengths[j - i + 3] * functions[(j - i) % 4]
            value *= stiffness[(1 if i >= 2 else 0) - (1 if j >= 2 else 0) + 1]
            if i > j:
                value *= w
            local[indices[i], indices[j]] = signs[i] * signs[j] * value


@njit(cache=True)
def _rod(stiffness, inertia, L, omega, rigid, local, a, b):
    """(displacement, force) block of an axial rod or shaft into ``local`` at rows/columns a, b."""
    if rigid:
        local[a, a] = 1.0
        local[b, b] = 1.0
        local[b, a] = inertia * omega * omega * L
        return
    kL = omega * L * math.sqrt(inertia / stiffness)
    sinc = np.sin(kL) / kL if kL != 0 else 1.0 + 0.0 * kL
    local[a, a] = np.cos(kL)
    local[b, b] = np.cos(kL)
    local[a, b] = -L / stiffness * sinc
    local[b, a] = stiffness / L * kL * kL * sinc


@njit(cache=True)
def beam_piece(beam, rotation, omega, length, out, local, functions, turned):
    """Inertial transfer matrix (12, 12) of a beam piece of ``length`` m at ``omega`` into ``out``:
    :func:`linmstmm.elements.beam.beam_transfer`.

    beam : (10,) (E, G, rho, A, Iy, Iz, J, Ip, length, flags), flags = axial + 2 torsion.
    rotation : (12, 12) state rotation of the traversal direction, of ``out``'s type.
    local, functions, turned : (12, 12), (4,) and (12, 12) of ``out``'s type, workspace.
    """
    E, G, rho, A, Iy, Iz, J, Ip = beam[0], beam[1], beam[2], beam[3], beam[4], beam[5], beam[6], beam[7]
    flags = int(beam[9])
    local[:, :] = 0.0
    _bending(E * Iz, rho * A, length, omega, local, _XY, _ONES, functions)
    _bending(E * Iy, rho * A, length, omega, local, _XZ, _XZ_SIGNS, functions)
    _rod(E * A, rho * A, length, omega, (flags & 1) == 0, local, 0, 9)
    _rod(G * J, rho * Ip, length, omega, (flags & 2) == 0, local, 3, 6)
    np.dot(rotation, local, turned)  # as numpy's rotation @ local @ rotation.T, to the bit
    np.dot(turned, rotation.T, out)


@njit(cache=True)
def _size(flat):
    """Largest |Re| + |Im| of ``flat`` (n,), NaN ignored."""
    first = second = third = fourth = 0.0  # four running maxima: no chain of comparisons
    whole = flat.size - flat.size % 4
    for start in range(0, whole, 4):
        first = max(first, _magnitude(flat[start]))
        second = max(second, _magnitude(flat[start + 1]))
        third = max(third, _magnitude(flat[start + 2]))
        fourth = max(fourth, _magnitude(flat[start + 3]))
    for i in range(whole, flat.size):
        first = max(first, _magnitude(flat[i]))
    return max(max(first, second), max(third, fourth))


@njit(cache=True, inline="always")
def _magnitude(v):
    """|Re| + |Im| of ``v``, 0 for NaN."""
    s = abs(v.real) + abs(v.imag)
    return s if s > 0.0 else 0.0


@intrinsic
def _view(typingctx, work, offset, rows, width):
    """``work[offset:offset + rows * width]`` (``work`` contiguous, 1-D) as a (rows, width)
    array: what ``reshape`` gives, without numba's call that works out the strides of a
    reshape of any layout (a few per cent of an evaluation). Unchecked: the program's
    slots lie inside the workspace."""
    if not (isinstance(work, types.Array) and work.ndim == 1 and work.layout == "C"):
        return None
    block = work.copy(ndim=2)

    def codegen(context, builder, signature, arguments):
        source = context.make_array(work)(context, builder, arguments[0])
        view = context.make_array(block)(context, builder)
        start, count, columns = arguments[1:]
        populate_array(view, data=cgutils.gep_inbounds(builder, source.data, start), shape=[count, columns],
                       strides=[builder.mul(columns, source.itemsize), source.itemsize], itemsize=source.itemsize,
                       meminfo=source.meminfo, parent=source.parent)
        return impl_ret_borrowed(context, builder, block, view._getvalue())
    return block(work, types.intp, types.intp, types.intp), codegen


@njit(cache=True)
def _multiply_add(matrix, source, target, place, rows):
    """target[:rows, place] += matrix[:rows] @ source (matrix (12, 12) float, source (12, k))."""
    for i in range(rows):
        for j in range(12):
            a = matrix[i, j]
            if a != 0.0:
                for c in range(source.shape[1]):
                    target[i, place[c]] += a * source[j, c]


@njit(cache=True)
def _multiply_rows(matrix, source, target):
    """target = matrix[:rows] @ source, target (rows, k), matrix (12, 12) float, source (12, k)."""
    target[:, :] = 0.0
    for i in range(target.shape[0]):
        for j in range(12):
            a = matrix[i, j]
            if a != 0.0:
                for c in range(source.shape[1]):
                    target[i, c] += a * source[j, c]


@njit(cache=True)
def _place_add(source, target, place, sign, rows):
    for i in range(rows):
        for c in range(source.shape[1]):
            target[i, place[c]] += sign * source[i, c]


@njit(cache=True)
def _unit_scale(columns, peak, kinds, scale, kind_size):
    """Row scales of the gathered blocks ``columns`` (k, rows), one unknown's column
    per row of the array, into ``scale`` (rows,): one per kind of row (``kinds``:
    0 displacement, 1 rotation, 2 moment, 3 force), the inverse root-mean-square size
    of all rows of that kind (:meth:`linmstmm.godunov._Orthonormaliser._unit_scale`).
    ``peak``: the :func:`_size` of ``columns``; ``kind_size`` (4,) is workspace."""
    width, rows = columns.shape
    peak = 2.0 ** np.round(np.log2(peak)) if peak > 0.0 else 1.0  # a power of two: exact division
    inverse_peak = 1.0 / peak
    scale[:] = 0.0  # the squares of each row first, relative to the peak: no overflow
    for c in range(width):
        for i in range(rows):
            v = columns[c, i] * inverse_peak
            scale[i] += v.real * v.real + v.imag * v.imag
    kind_size[:] = 0.0
    for i in range(rows):
        kind_size[kinds[i]] += scale[i]
    for kind in range(4):
        kind_size[kind] = math.sqrt(kind_size[kind])
    largest = kind_size.max()
    for i in range(rows):
        size = kind_size[kinds[i]] if kind_size[kinds[i]] > 0 else largest
        scale[i] = 1.0 / (size * peak) if size > 0 else 1.0  # all rows zero: any scale


#: A Gram–Schmidt pass that leaves a column more than this fraction of its squared
#: norm is orthogonal to rounding; one that leaves less is repeated once ("twice is
#: enough", Kahan and Parlett; Giraud, Langou and Rozložník 2005).
_KEPT_ENOUGH = 0.5


@njit(cache=True, inline="always")
def _dots(columns, p, q, j):
    """(Σ conj(columns[p]) columns[j], Σ conj(columns[q]) columns[j]), each in four
    interleaved partial sums added in a fixed order: the same rounding wherever numba
    compiles it (a reassociated sum is vectorised as each caller's context allows, and
    rounds differently). Two at once share the loads of ``columns[j]`` and keep eight
    sums in flight."""
    m = columns.shape[1]
    a0 = a1 = a2 = a3 = b0 = b1 = b2 = b3 = 0.0 * columns[j, 0]
    whole = m - m % 4
    for i in range(0, whole, 4):
        x0, x1, x2, x3 = columns[j, i], columns[j, i + 1], columns[j, i + 2], columns[j, i + 3]
        a0 += np.conj(columns[p, i]) * x0
        a1 += np.conj(columns[p, i + 1]) * x1
        a2 += np.conj(columns[p, i + 2]) * x2
        a3 += np.conj(columns[p, i + 3]) * x3
        b0 += np.conj(columns[q, i]) * x0
        b1 += np.conj(columns[q, i + 1]) * x1
        b2 += np.conj(columns[q, i + 2]) * x2
        b3 += np.conj(columns[q, i + 3]) * x3
    for i in range(whole, m):
        a0 += np.conj(columns[p, i]) * columns[j, i]
        b0 += np.conj(columns[q, i]) * columns[j, i]
    return (a0 + a1) + (a2 + a3), (b0 + b1) + (b2 + b3)


@njit(cache=True, inline="always")
def _dot(columns, p, j):
    """Σ conj(columns[p]) columns[j], as :func:`_dots` sums it."""
    return _dots(columns, p, p, j)[0]


@njit(cache=True)
def _orthonormal_columns(columns, diagonal, projections):
    """Orthonormalise the rows of ``columns`` (k, m) in place: classical Gram–Schmidt,
    each column's pass repeated once where it cancelled more than half of the
    column's squared norm (orthogonal to rounding either way), the QR of its
    transpose with R's diagonal real and positive (the basis is smooth in ω).
    ``diagonal`` (k,) receives R's diagonal; ``projections`` (k,) is workspace.
    Returns False, leaving ``columns`` partly changed, if a column depends exactly
    on the ones before it (at a root)."""
    k, m = columns.shape
    for j in range(k):
        norm = _dot(columns, j, j).real
        if norm == 0.0:
            return False
        for _ in range(2):
            before = norm
            for p in range(0, j - 1, 2):  # every projection from the same column: independent sums
                projections[p], projections[p + 1] = _dots(columns, p, p + 1, j)
            if j % 2:
                projections[j - 1] = _dot(columns, j - 1, j)
            for p in range(j):
                for i in range(m):
                    columns[j, i] -= projections[p] * columns[p, i]
            norm = _dot(columns, j, j).real
            if norm > _KEPT_ENOUGH * before:
                break
        if norm == 0.0:
            return False
        norm = math.sqrt(norm)
        diagonal[j] = norm
        for i in range(m):
            columns[j, i] /= norm
    return True


@njit(cache=True)
def _gathered(program, index, work_m, columns, kinds):
    """The blocks of orthonormalisation record ``index`` stacked on its columns, one
    unknown per row of ``columns`` (width, rows), zero where a block has no column or
    past the blocks' rows, and each row's kind into ``kinds`` (0 past the blocks' rows)."""
    (slot_offset, slot_rows, slot_width, places, places_start, orthos, blocks) = program
    first, count = orthos[index, 0], orthos[index, 1]
    width, total = columns.shape
    row = 0
    for b in range(first, first + count):
        src, rows, place_index = blocks[b, 0], blocks[b, 2], blocks[b, 4]
        source = _view(work_m, slot_offset[src], rows, slot_width[src])
        if place_index < 0:  # on all the columns
            for i in range(rows):
                for c in range(source.shape[1]):
                    columns[c, row + i] = source[i, c]
        else:
            for c in range(width):
                for i in range(rows):
                    columns[c, row + i] = 0.0
            place = places[places_start[place_index]:places_start[place_index + 1]]
            for i in range(rows):
                for c in range(source.shape[1]):
                    columns[place[c], row + i] = source[i, c]
        forces = blocks[b, 5]  # a joint's row: force rows, then moment rows
        for i in range(rows):
            kinds[row + i] = i // 3 if forces < 0 else (3 if i < forces else 2)
        row += rows
    for i in range(row, total):
        kinds[i] = 0
        for c in range(width):
            columns[c, i] = 0.0


@njit(cache=True)
def _scattered(program, index, columns, scale, work_m, reference_m):
    """Write the orthonormalised ``columns`` (width, rows) back into the record's
    blocks, each row divided by its ``scale`` (which this overwrites with its inverse);
    returns the log of the common power of two taken out of them past :data:`FAR`
    (0 if none)."""
    (slot_offset, slot_rows, slot_width, places, places_start, orthos, blocks) = program
    first, count, width = orthos[index, 0], orthos[index, 1], orthos[index, 3]
    back = scale
    for i in range(scale.size):
        back[i] = 1.0 / scale[i]
    peak = 0.0
    row = 0
    for b in range(first, first + count):
        dst, rows, kind = blocks[b, 1], blocks[b, 2], blocks[b, 3]
        target = _view(work_m, slot_offset[dst], rows, width)
        for i in range(rows):
            for c in range(width):
                target[i, c] = columns[c, row + i] * back[row + i]
        size = _size(work_m[slot_offset[dst]:slot_offset[dst] + rows * width])
        peak = max(peak, size)
        if kind == STATE_BLOCK:
            reference_m[dst] = size
        row += rows
    if not (peak > FAR or peak < 1 / FAR):
        return 0.0
    common = 2.0 ** (-np.round(np.log2(peak)))  # a power of two: every entry and size scales exactly
    for b in range(first, first + count):
        dst, rows, kind = blocks[b, 1], blocks[b, 2], blocks[b, 3]
        start = slot_offset[dst]
        work_m[start:start + rows * width] *= common
        if kind == STATE_BLOCK:
            reference_m[dst] *= common
    return math.log(common)


@njit(cache=True)
def _orthonormal_scratch(orthos, blocks, group, like):
    """Workspace of :func:`_orthonormalise` for every record of ``orthos`` (O, 5) with
    ``blocks`` (B, 6), for ``group`` frequencies of the type of the array ``like``:
    (columns (g, k·rows), kinds (rows,), scale (g, rows), diagonals (g, k),
    projections (k,), kind sizes (4,)), k and rows the most any record takes."""
    width = 1
    total = 4
    for index in range(orthos.shape[0]):
        width = max(width, orthos[index, 3])
        total = max(total, _padded_rows(orthos, blocks, index))
    return (np.empty((group, width * total), dtype=like.dtype), np.empty(total, dtype=np.int64),
            np.empty((group, total)), np.empty((group, width)), np.empty(width, dtype=like.dtype),
            np.empty(4))


@njit(cache=True)
def _padded_rows(orthos, blocks, index):
    """Rows of record ``index``'s blocks, padded with zeros to a multiple of four:
    Gram–Schmidt's sums run in whole vectors."""
    total = 3
    for b in range(orthos[index, 0], orthos[index, 0] + orthos[index, 1]):
        total += blocks[b, 2]
    return total - total % 4


@njit(cache=True)
def _grown(program, index, work, reference, group):
    """Whether record ``index`` is due: its state grew or shrank by :data:`GROWTH` or more
    since its reference in some member of the group (or has none)."""
    (slot_offset, slot_rows, slot_width, places, places_start, orthos, blocks) = program
    state_src = blocks[orthos[index, 0] + orthos[index, 2], 0]
    for m in range(group):
        ref = reference[m, state_src]
        if math.isnan(ref) or ref == 0.0:  # no reference, or grown from nothing (numpy: inf)
            return True
        start = slot_offset[state_src]
        growth = _size(work[m, start:start + slot_rows[state_src] * slot_width[state_src]]) / ref
        if not (growth < GROWTH and growth > 1 / GROWTH):
            return True
    return False


@njit(cache=True)
def _laid_out(program, index, work, reference, group):
    """Lay record ``index``'s blocks out on its columns, nothing else."""
    (slot_offset, slot_rows, slot_width, places, places_start, orthos, blocks) = program
    first, count, width = orthos[index, 0], orthos[index, 1], orthos[index, 3]
    for m in range(group):
        for b in range(first, first + count):
            src, dst, rows, place_index = blocks[b, 0], blocks[b, 1], blocks[b, 2], blocks[b, 4]
            if place_index < 0:
                continue
            source = _view(work[m], slot_offset[src], rows, slot_width[src])
            target = _view(work[m], slot_offset[dst], rows, width)
            target[:, :] = 0.0
            place = places[places_start[place_index]:places_start[place_index + 1]]
            _place_add(source, target, place, 1.0, rows)
            if blocks[b, 3] == STATE_BLOCK:
                reference[m, dst] = reference[m, src]


@njit(cache=True)
def _orthonormalise(program, index, work, reference, log_scale, group, scratch):
    """Orthonormalisation record ``index`` for the ``group`` members' workspaces ``work``
    (g, W), in ``scratch`` (:func:`_orthonormal_scratch`)."""
    (slot_offset, slot_rows, slot_width, places, places_start, orthos, blocks) = program
    columns_all, kinds_all, scale_all, diagonals, projections, kind_size = scratch
    width, total = orthos[index, 3], _padded_rows(orthos, blocks, index)
    if orthos[index, 4] != 0 or not _grown(program, index, work, reference, group):
        _laid_out(program, index, work, reference, group)
        return
    kinds = kinds_all[:total]
    for m in range(group):
        columns = _view(columns_all[m], 0, width, total)  # each unknown's column, contiguous
        _gathered(program, index, work[m], columns, kinds)
        scale = scale_all[m, :total]
        _unit_scale(columns, _size(columns_all[m, :width * total]), kinds, scale, kind_size)
        for c in range(width):
            for i in range(total):
                columns[c, i] *= scale[i]
        if not _orthonormal_columns(columns, diagonals[m, :width], projections[:width]):
            _laid_out(program, index, work, reference, group)  # exactly dependent (at a root): kept as they are
            return
    for m in range(group):
        for c in range(width):
            log_scale[m] += math.log(diagonals[m, c])
        log_scale[m] -= _scattered(program, index, _view(columns_all[m], 0, width, total), scale_all[m, :total],
                                   work[m], reference[m]) * width


@njit(cache=True)
def _beam_scratch(program, group, like):
    """Workspace of the beams' carries in :func:`_run` for ``group`` frequencies of the type
    of the array ``like``: (pieces (nb,), each beam's piece per frequency (nb, g, 12, 12),
    the rotations (nb, 12, 12), local (12, 12), Krylov functions (4,), turned (12, 12),
    a carried state (12·k,) of the widest slot)."""
    (slot_offset, slot_rows, slot_width, operations, terms, places, places_start, matrices,
     orthos, ortho_blocks, beams, beam_rotation) = program
    count = beams.shape[0]
    return (np.ones(count, dtype=np.int64), np.empty((count, group, 12, 12), dtype=like.dtype),
            beam_rotation.astype(like.dtype), np.empty((12, 12), dtype=like.dtype),
            np.empty(4, dtype=like.dtype), np.empty((12, 12), dtype=like.dtype),
            np.empty(12 * max(slot_width.max(), 1), dtype=like.dtype))


@njit(cache=True)
def _run(program, omegas, work, reference, log_scale, ortho_scratch, beam_scratch):
    """Replay the operations for one group of frequencies ``omegas`` (g,), in the
    workspaces of :func:`_orthonormal_scratch` and :func:`_beam_scratch`."""
    program, work, reference, log_scale = _unowned((program, work, reference, log_scale))  # kept by the caller
    ortho_scratch, beam_scratch = _unowned((ortho_scratch, beam_scratch))
    (slot_offset, slot_rows, slot_width, operations, terms, places, places_start, matrices,
     orthos, ortho_blocks, beams, beam_rotation) = program
    ortho_program = (slot_offset, slot_rows, slot_width, places, places_start, orthos, ortho_blocks)
    pieces, piece, rotations, local, functions, turned, carried = beam_scratch
    group = omegas.size
    largest = 0.0
    for m in range(group):
        largest = max(largest, abs(omegas[m]))
    pieces[:] = 1
    for op in range(operations.shape[0]):
        code, a, b, c, d = (operations[op, 0], operations[op, 1], operations[op, 2], operations[op, 3],
                            operations[op, 4])
        if code == ORTHO:
            _orthonormalise(ortho_program, a, work, reference, log_scale, group, ortho_scratch)
            continue
        for m in range(group):
            if code == TIP:
                target = _view(work[m], slot_offset[a], 12, slot_width[a])
                target[:, :] = matrices[b, :, :slot_width[a]]
                reference[m, a] = 1.0
            elif code == CARRY:
                target = _view(work[m], slot_offset[a], 12, slot_width[a])
                source = _view(work[m], slot_offset[b], 12, slot_width[b])
                _multiply_rows(matrices[c], source, target)
                if d >= 0:
                    w2 = omegas[m] * omegas[m]
                    inertial = matrices[d]
                    for i in range(6, 12):
                        for j in range(6):
                            coefficient = inertial[i, j]
                            if coefficient != 0.0:
                                for k in range(source.shape[1]):
                                    target[i, k] += w2 * coefficient * source[j, k]
                reference[m, a] = reference[m, b]
            elif code == JOINT:
                target = _view(work[m], slot_offset[a], slot_rows[a], slot_width[a])
                _multiply_rows(matrices[c], _view(work[m], slot_offset[b], 12, slot_width[b]), target)
            elif code == GEOMETRIC:
                target = _view(work[m], slot_offset[a], 6, slot_width[a])
                first = _view(work[m], slot_offset[b], 12, slot_width[b])
                other = _view(work[m], slot_offset[c], 12, slot_width[c])
                target[:, :] = 0.0
                place_first = places[places_start[operations[op, 5]]:places_start[operations[op, 5] + 1]]
                place_other = places[places_start[operations[op, 5] + 1]:places_start[operations[op, 5] + 2]]
                _place_add(first, target, place_first, -1.0, 6)
                _multiply_add(matrices[d], other, target, place_other, 6)
            elif code == COMBINE:
                target = _view(work[m], slot_offset[a], 12, slot_width[a])
                target[:, :] = 0.0
                ref = 0.0
                known = True
                for t in range(b, b + c):
                    src, matrix, place_index = terms[t, 0], terms[t, 1], terms[t, 2]
                    source = _view(work[m], slot_offset[src], 12, slot_width[src])
                    place = places[places_start[place_index]:places_start[place_index + 1]]
                    if matrix < 0:
                        _place_add(source, target, place, 1.0, 12)
                    else:
                        _multiply_add(matrices[matrix], source, target, place, 12)
                    known = known and not math.isnan(reference[m, src])
                    ref = max(ref, reference[m, src])
                reference[m, a] = ref if known else np.nan
        if code == BEAM:
            beam = beams[b]
            if c == 1:
                softer = min(beam[4], beam[5])
                beta_L = (beam[2] * beam[3] * largest ** 2 / (beam[0] * softer)) ** 0.25 * beam[8]
                pieces[b] = max(int(math.ceil(beta_L / BEAM_PIECE_BETA_L)), 1)
                for m in range(group):
                    beam_piece(beam, rotations[b], omegas[m], beam[8] / pieces[b], piece[b, m], local, functions,
                               turned)
            for repeat in range(1 if c == 1 else pieces[b] - 1):
                for m in range(group):
                    state = _view(work[m], slot_offset[a], 12, slot_width[a])
                    before = _view(carried, 0, 12, slot_width[a])
                    before[:, :] = state
                    np.dot(piece[b, m], before, state)  # BLAS's product, as numpy's
                if c == 0 and d >= 0:
                    _orthonormalise(ortho_program, d, work, reference, log_scale, group, ortho_scratch)


@njit(cache=True)
def _assembled(work_m, sources, targets, transposed, order):
    """Ū_all (N, N), N = ``order``, of one frequency from its workspace ``work_m``, in
    Fortran order (what LAPACK factorises, without reordering): the transpose of
    ``transposed`` (N², ) row by row, which it overwrites with entry ``sources[e]`` of the
    workspace added at index ``targets[e]`` for each e in turn (see
    :func:`linmstmm.determinant._assembly`)."""
    transposed[:] = 0.0
    for e in range(sources.size):
        transposed[targets[e]] += work_m[sources[e]]
    return _view(transposed, 0, order, order).T


_DGETRF, _ZGETRF = lapack_routine("dgetrf", 6), lapack_routine("zgetrf", 6)


@njit(cache=True)
def _log_det(matrix):
    """(sign or phase, log|det|) of ``matrix`` (N, N), Fortran-ordered, which it
    overwrites with its LU factors: what numpy's slogdet computes (LAPACK's getrf),
    without a copy. (NaN, NaN) where a pivot is not finite (an entry was not: numba's
    slogdet raises there), which the root counts step round."""
    n = matrix.shape[0]
    integers = np.array([n, n, 0], dtype=np.int32)  # order, leading dimension, info
    pivots = np.empty(n, dtype=np.int32)
    if matrix.itemsize == 16:  # complex128
        _ZGETRF(integers.ctypes, integers.ctypes, matrix.ctypes, integers[1:].ctypes, pivots.ctypes,
                integers[2:].ctypes)
    else:
        _DGETRF(integers.ctypes, integers.ctypes, matrix.ctypes, integers[1:].ctypes, pivots.ctypes,
                integers[2:].ctypes)
    sign = 1.0 + 0.0 * matrix[0, 0]
    for k in range(n):
        if pivots[k] != k + 1:
            sign = -sign
    log_abs = 0.0
    for k in range(n):
        magnitude = np.abs(matrix[k, k])
        if magnitude > 0.0:
            sign = sign * (matrix[k, k] / magnitude)
        log_abs += np.log(magnitude)
    if math.isnan(log_abs) or log_abs == np.inf:
        return np.nan + 0.0 * sign, np.nan
    if integers[2] > 0:  # an exactly zero pivot
        return sign - sign, -np.inf  # a zero of sign's type, +0
    return sign, log_abs


@njit(cache=True)
def _block_log_det(work_m, sources, targets, blocks, offsets, orders, permutation_sign):
    """(sign or phase, log|det Ū_all|) of one frequency's workspace ``work_m`` from the
    diagonal blocks of Ū_all's block-triangular form: ``blocks`` (F,) is overwritten
    with them (entry ``sources[e]`` of the workspace added at ``targets[e]``, each block
    Fortran-ordered from ``offsets[k]``, of order ``orders[k]``), and det Ū_all =
    ``permutation_sign`` · Π det(block) (:func:`linmstmm._assembly_kernels.determinant_blocks`).
    As :func:`_log_det`: (NaN, NaN) where an entry is not finite, (+0, −inf) where a
    pivot is exactly zero; a block of order one is its own pivot."""
    blocks[:] = 0.0
    for e in range(sources.size):
        blocks[targets[e]] += work_m[sources[e]]
    sign = permutation_sign + 0.0 * work_m[0]
    log_abs = 0.0
    for k in range(orders.size):
        if orders[k] == 1:
            pivot = blocks[offsets[k]]
            magnitude = np.abs(pivot)
            block_sign, block_log = (pivot / magnitude if magnitude > 0.0 else pivot - pivot), np.log(magnitude)
            if math.isnan(block_log) or block_log == np.inf:
                block_log = np.nan
        else:
            block_sign, block_log = _log_det(_view(blocks, offsets[k], orders[k], orders[k]).T)
        if math.isnan(block_log):
            return np.nan + 0.0 * sign, np.nan
        sign = sign * block_sign
        log_abs += block_log
    if log_abs == -np.inf:
        return sign - sign, -np.inf  # a zero of sign's type, +0
    return sign, log_abs


@njit(cache=True, nogil=True)
def evaluate(program, layout, omegas, group, matrices_out, sign_out, log_abs_out, log_scale_out):
    """Stable Ū_all over ``omegas`` (n,) in groups of ``group`` consecutive frequencies.

    matrices_out : (n, N, N) or (0, N, N) to skip storing Ū_all. sign_out,
    log_abs_out : (n,) sign (phase) and log|det Ū_all| (log-scale included);
    log_scale_out : (n,) the log-scale alone (det Ū_all = det(matrix) e^log_scale).
    """
    workspace, n_slots, kept, sources, targets, block_sources, block_targets, offsets, orders, block_sign = layout
    n = omegas.size
    largest = min(group, n)
    # every operation writes the whole of its target: the workspace needs no clearing
    whole = np.empty((largest, workspace), dtype=omegas.dtype)
    references, log_scales = np.empty((largest, n_slots)), np.empty(largest)
    orthos, ortho_blocks = program[8], program[9]
    ortho_scratch = _orthonormal_scratch(orthos, ortho_blocks, largest, omegas)
    beam_scratch = _beam_scratch(program, largest, omegas)
    transposed = np.empty(kept * kept if matrices_out.shape[0] else 0, dtype=omegas.dtype)
    blocks = np.empty(offsets[-1], dtype=omegas.dtype)
    for start in range(0, n, group):
        stop = min(start + group, n)
        size = stop - start
        work, reference, log_scale = whole[:size], references[:size], log_scales[:size]
        reference[:, :] = np.nan
        log_scale[:] = 0.0
        _run(program, omegas[start:stop], work, reference, log_scale, ortho_scratch, beam_scratch)
        for m in range(size):
            if matrices_out.shape[0]:
                matrices_out[start + m] = _assembled(work[m], sources, targets, transposed, kept)
            # NaN where not finite, which the root counts step round
            sign, log_abs = _block_log_det(work[m], block_sources, block_targets, blocks, offsets, orders,
                                           block_sign)
            sign_out[start + m] = sign
            log_abs_out[start + m] = log_abs + log_scale[m]
            log_scale_out[start + m] = log_scale[m]
