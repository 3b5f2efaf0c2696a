#pragma once
// Internal to common/: what a .vtu file must pass before VTK's XML reader sees it. VTK 9.1's reader
// trusts the counts and the block headers of a file: a corrupted one makes it divide by zero, read
// past its buffers or ask for exabytes (issue 10; fuzz/corpus/vtu and tests/common/bad_files/).

#include <filesystem>

namespace fem::io::detail {

/// Checks the layout of an unstructured grid file against what it holds, without VTK: one
/// <VTKFile type="UnstructuredGrid"> with one <Piece>; plain XML tags (no comments, CDATA or entity
/// references); header_type UInt32 or UInt64; no compressor or zlib; every <DataArray> of a known
/// numeric type, 1 to 1024 components, format ascii, binary or appended; each holding exactly the
/// values its place needs (points: 3 per point, point and cell fields: one tuple per point or cell,
/// cell types: one per cell, field data: NumberOfTuples), read from its ASCII tokens, its
/// base64 text or its appended bytes, its compressed blocks each within zlib's largest ratio; and
/// cell offsets that never decrease and stay within the connectivity. fem::Error naming the file and
/// what is wrong otherwise.
void check_vtu_layout(const std::filesystem::path& path);

}  // namespace fem::io::detail
