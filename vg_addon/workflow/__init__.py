"""How measurements are driven, without Blender: the batch plan (``batchplan``: which rows are
measured on which mesh), the click-and-drag tool's state machine (``drag_state``), the edge-profile
clicks' (``edge_state``), and where measurement labels go on a picture and which views a
measurement map has (``labels``)."""
