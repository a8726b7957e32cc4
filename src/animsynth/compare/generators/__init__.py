"""The generators the comparison runs, one module each, and the registry that builds them by row name.

registry        row names -> estimators and their settings (``make_generator``), no method code
names           the row names (``GENERATORS``, ``FAIRMOTION_ROWS``, ``REFERENCES``, ``DETERMINISTIC``) and the rows
                of one method that share a workflow job (``METHOD_ROWS``): a leaf module the harness reads without
                importing a generator
motiongraph     the classic motion graph (Kovar, Gleicher & Pighin 2002)
point_clouds    joint-position point clouds and their closed-form floor alignment (both graphs compare with it)
fairmotion_peer fairmotion's motion graph on the same clips (the peer row), when it can be imported
fairmotion_fixes the named fixes of fairmotion's walk (the row fairmotion_fixed) and the recorder of its walk
fairmotion_load the clips fed to fairmotion (BVH, upsampling) and its loading and construction memos
motionmatching  motion matching with inertialization (Clavet 2016; Holden et al. 2020); footlock: its foot locking
                and leg IK
genmm           generative motion matching (Li et al. 2023)
poses           the pose representation motion matching and GenMM share
references      the two reference rows: replay (the held-out capture) and concat (random segments)
user            your own generator in the comparison (``compare.user_generators``: a file and a class)
user_guard      what keeps a user class inside its job: the write and signal guard, the watchdog (standard library)

Every generator is an :class:`animsynth.generator.Generator` (the one import path of the interface).
"""
