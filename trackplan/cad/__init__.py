"""Seams from a part's CAD model: the part's faces and edges, and the seams derived from them
(``docs/cad.md``). The files are read in :mod:`trackplan.io` (STEP through OpenCascade, meshes
through trimesh) into a :class:`~trackplan.cad.part.PartModel`; this package derives the
seams' segments and weld normals from any part model.
"""
