"""The autopilot's loop gains read from its parameters (definition file ``autopilot.xml``, a
:class:`~fdm_awe.autopilot.params.ParamStore`): the guidance's gains and limits and the attitude
loops' gains.
"""

from __future__ import annotations

from ..sixdof.attitude_law import StabilizerGains
from .guidance_loop import GuidanceGains
from .params import ParamStore

#: the attitude loops' parameters -> the :class:`~fdm_awe.sixdof.attitude_law.StabilizerGains` field each sets
STAB_PARAMS = {"W_ALPHA": "w_alpha", "Z_ALPHA": "z_alpha", "KI_ALPHA": "ki_alpha", "W_PHI": "w_phi",
               "Z_PHI": "z_phi", "W_R": "w_r", "K_BETA": "k_beta"}


def stabilizer_gains(p: ParamStore) -> StabilizerGains:
    """The attitude loops' gains from the parameters ``p`` (:data:`STAB_PARAMS`)."""
    return StabilizerGains(**{v: p[k] for k, v in STAB_PARAMS.items()})


def guidance_gains(p: ParamStore) -> GuidanceGains:
    """The guidance's gains and limits from the parameters ``p`` (GUID_*, LIM_*, US_*, GP_*)."""
    return GuidanceGains(
        kp=p["GUID_KP"], kd=p["GUID_KD"], ki=p["GUID_KI"], a_max=p["GUID_AMAX"], int_max=p["GUID_IMAX"],
        alpha_min=p["LIM_ALPHA_MIN"], alpha_max=p["LIM_ALPHA_MAX"], phi_max=p["LIM_BANK"], thrust_max=p["LIM_THRUST"],
        energy_trade=p["GUID_ETRADE"], negative_lift=p["GUID_NEGLIFT"] > 0.5, phi_max_vertical=p["LIM_BANK_VERT"],
        curv_scale_max=p["GUID_CURVMAX"], bank_lift=p["GUID_MU_LIFT"],
        overspeed_tension=p["GUID_VTENS"], overspeed_margin=p["GUID_VMARGIN"],
        us_enter=p["US_V_ENTER"], us_exit=p["US_V_EXIT"], us_hold=p["US_HOLD"], us_alpha_margin=p["US_ALPHA_MARG"],
        us_speed_gain=p["US_KV"], us_slack_acc=p["US_SLACK_A"], us_margin_speed=p["US_AMARG_V"],
        gp_alt=p["GP_ALT"], gp_acc=p["GP_ACC"], gp_climb=p["GP_CLIMB"],
    )
