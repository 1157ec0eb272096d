"""skvalve: heart-valve tissue mechanics on scikit-fem.

Reproduces, explains and extends
- Buchanan & Sacks (2014), layered aortic leaflet in flexure,
- Thomas et al. (2019), multiscale (FE^2) tricuspid leaflet with collagen-fiber networks,
- Mathur et al. (2022), the Texas TriValve whole tricuspid-valve model.
"""

__version__ = "0.1.0"
