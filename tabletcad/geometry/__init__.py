"""The numerical geometry of a tablet (numpy and scipy only).

The first stages of the flow: the PDE's cardinal functions (:mod:`.basis`), the
closed boundary curves a design is made of (:mod:`.curves`), the Bloor-Wilson PDE
patches they bound (:mod:`.patch`), and the tablet, a chain of patches with its
trims, checks and solid map (:mod:`.tablet`).  :mod:`.nominal` holds the exact
nominal shapes of the thesis's tablets as signed distance functions; :mod:`.lettering` an engraved
figure's plan curves (a font's glyphs, as OCC lays them out) and how much of it lies outside a face,
:mod:`.glyphs` a TrueType glyph's points as FreeType rounds them for OCC.
"""
