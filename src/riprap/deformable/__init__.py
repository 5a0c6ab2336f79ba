"""Deformable bodies (the seed's Y3D-D): explicit finite-strain tetrahedra with stresses."""
from riprap.deformable.body import DeformableBody
from riprap.deformable.material import CONSTITUTIVE_MODELS, ElasticMaterial
from riprap.deformable.stresses import principal_stresses, von_mises
from riprap.geometry.structured import box_mesh

__all__ = ["CONSTITUTIVE_MODELS", "DeformableBody", "ElasticMaterial", "box_mesh",
           "principal_stresses", "von_mises"]
