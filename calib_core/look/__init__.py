"""The look: a known object found in a camera image, from its mesh, the camera's intrinsics and a rough pose.

What it reads from an image (:mod:`~calib_core.look.image_evidence`: grey, gradients, edges and their distance map,
colours, at full size and halved, computed once); where the object's outline and creases fall at a pose
(:mod:`~calib_core.look.outline`, :mod:`~calib_core.look.edge_samples`); where its colours end
(:mod:`~calib_core.look.region_model`); the edge fit that pulls the pose onto the image's edges
(:mod:`~calib_core.look.edge_refinement`, anchored by :mod:`~calib_core.look.pose_prior` on a photograph); the starts
it is tried from (:mod:`~calib_core.look.pose_hypotheses`) and which of their fits is kept
(:mod:`~calib_core.look.fit_choice`); the features' detectors (:mod:`~calib_core.look.target_detectors`); Find points,
which proposes pairs in the window (:mod:`~calib_core.look.find_points`; on the image halved for a part whose
:mod:`~calib_core.look.form_tolerance` is more pixels than the fit averages over, :mod:`~calib_core.look.halved_look`);
and a look on any photograph with its verdict (:mod:`~calib_core.look.locate`, :mod:`~calib_core.look.locate_verdict`).
The camera's own calibration (boards, intrinsics, hand-eye) is :mod:`calib_core.vision`.
"""
