"""Closed-form and 1-D root-solved reference solutions."""

from .homogeneous import HomogeneousResponse, biaxial, equibiaxial, uniaxial

__all__ = ["HomogeneousResponse", "uniaxial", "equibiaxial", "biaxial"]
