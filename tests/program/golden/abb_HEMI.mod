MODULE MOD_HEMI
  ! waam-slicer: ABB IRB 2600 part carried (example layout), 20 points, 2 beads
  ! entry routine HEMI (call it from the task's main); every other name is LOCAL to this module
  ! stationary torch (tWaam), part held by the robot (wWaam): speeds are the torch's over the part
  ! tWaam.tload: load0: set [program] payload_base_kg or payload_every_layers for the part the robot holds
  LOCAL PERS tooldata tWaam := [FALSE,[[1000.0000,0.0000,900.0000],[0.0000000,1.0000000,0.0000000,0.0000000]],[0.0010,[0.0000,0.0000,0.0010],[1,0,0,0],0.000000,0.000000,0.000000]];
  LOCAL PERS wobjdata wWaam := [TRUE,TRUE,"",[[0.0000,0.0000,0.0000],[0.7071068,0.0000000,-0.7071068,0.0000000]],[[0,0,0],[1,0,0,0]]];
  ! ArcWare data (RobotWare 6 Arc): process schedule 1 (arcdata.sched); one welddata per planned travel speed (weld_speed, mm/s) and wire feed (main_arc.wirefeed, m/min)
  ! gas (s): purge_time 0.500, preflow_time 0.300, postflow_time 1.500 ([program.abb] purge_time_s, preflow_time_s, postflow_time_s)
  LOCAL PERS seamdata seamWaam := [0.500,0.300,[1,0,0,0,0,0,0,0,0],0,0,0,0,0,[0,0,0,0,0,0,0,0,0],0,0,[0,0,0,0,0,0,0,0,0],0,0,[0,0,0,0,0,0,0,0,0],1.500];
  LOCAL PERS welddata weldWaam1 := [6.0000,0,[1,0,0,0.6000,0,0,0,0,0],[0,0,0,0,0,0,0,0,0]];
  LOCAL CONST robtarget p1 := [[45.0000,0.0000,20.0000],[0.0000000,1.0000000,0.0000000,0.0000000],[0,0,0,1],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST jointtarget j1 := [[0.00000,4.04064,39.36673,0.00000,-43.40737,0.00000],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p2 := [[45.0000,0.0000,0.0000],[0.0000000,1.0000000,0.0000000,0.0000000],[0,0,0,1],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p3 := [[31.8198,31.8198,0.0000],[0.0000000,1.0000000,0.0000000,0.0000000],[-1,-1,0,1],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p4 := [[0.0000,45.0000,0.0000],[0.0000000,1.0000000,0.0000000,0.0000000],[-1,-1,0,1],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p5 := [[-31.8198,31.8198,0.0000],[0.0000000,1.0000000,0.0000000,0.0000000],[-1,-1,0,1],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p6 := [[-45.0000,0.0000,0.0000],[0.0000000,1.0000000,0.0000000,0.0000000],[0,0,0,1],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p7 := [[-31.8198,-31.8198,0.0000],[0.0000000,1.0000000,0.0000000,0.0000000],[0,0,-1,1],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p8 := [[0.0000,-45.0000,0.0000],[0.0000000,1.0000000,0.0000000,0.0000000],[0,0,-1,1],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p9 := [[31.8198,-31.8198,0.0000],[0.0000000,1.0000000,0.0000000,0.0000000],[0,0,-1,1],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p10 := [[31.8198,-31.8198,20.0000],[0.0000000,1.0000000,0.0000000,0.0000000],[0,0,-1,1],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p11 := [[42.5049,0.0000,24.8664],[0.0000000,0.9984572,0.0000000,0.0555270],[0,0,0,1],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST jointtarget j11 := [[0.00000,3.67355,38.94896,0.00000,-36.25632,0.00000],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p12 := [[44.7225,0.0000,4.9897],[0.0000000,0.9984572,0.0000000,0.0555270],[0,0,0,1],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p13 := [[31.6236,31.6236,4.9897],[0.0392027,-0.9984560,-0.0015440,-0.0393242],[-1,-1,-1,1],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p14 := [[0.0000,44.7225,4.9897],[0.0555270,-0.9984572,0.0000000,0.0000000],[-1,-1,-1,1],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p15 := [[-31.6236,31.6236,4.9897],[0.0392027,-0.9984560,0.0015440,0.0393242],[-1,-1,-1,1],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p16 := [[-44.7225,0.0000,4.9897],[0.0000000,0.9984572,0.0000000,-0.0555270],[0,0,0,1],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p17 := [[-31.6236,-31.6236,4.9897],[0.0392027,0.9984560,0.0015440,-0.0393242],[0,0,0,1],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p18 := [[0.0000,-44.7225,4.9897],[0.0555270,0.9984572,0.0000000,0.0000000],[0,0,0,1],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p19 := [[31.6236,-31.6236,4.9897],[0.0392027,0.9984560,-0.0015440,0.0393242],[0,0,0,1],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p20 := [[30.0555,-30.0555,24.8664],[0.0392027,0.9984560,-0.0015440,0.0393242],[0,0,0,1],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  PROC HEMI()
    ConfL \On;
    ! bead 0 (layer 0): approach
    MoveAbsJ j1, [100.0000,500,5000,1000], fine, tWaam\WObj:=wWaam;
    ArcLStart p2, [20.0000,500,5000,1000], seamWaam, weldWaam1, fine, tWaam\WObj:=wWaam;
    ArcL p3, [6.0000,500,5000,1000], seamWaam, weldWaam1, z1, tWaam\WObj:=wWaam;
    ArcL p4, [6.0000,500,5000,1000], seamWaam, weldWaam1, z1, tWaam\WObj:=wWaam;
    ArcL p5, [6.0000,500,5000,1000], seamWaam, weldWaam1, z1, tWaam\WObj:=wWaam;
    ArcL p6, [6.0000,500,5000,1000], seamWaam, weldWaam1, z1, tWaam\WObj:=wWaam;
    ArcL p7, [6.0000,500,5000,1000], seamWaam, weldWaam1, z1, tWaam\WObj:=wWaam;
    ArcL p8, [6.0000,500,5000,1000], seamWaam, weldWaam1, z1, tWaam\WObj:=wWaam;
    ArcLEnd p9, [6.0000,500,5000,1000], seamWaam, weldWaam1, fine, tWaam\WObj:=wWaam;
    MoveL p10, [20.0000,500,5000,1000], fine, tWaam\WObj:=wWaam;
    ! bead 1 (layer 1): approach
    MoveAbsJ j11, [100.0000,500,5000,1000], fine, tWaam\WObj:=wWaam;
    ArcLStart p12, [20.0000,500,5000,1000], seamWaam, weldWaam1, fine, tWaam\WObj:=wWaam;
    ArcL p13, [6.0000,500,5000,1000], seamWaam, weldWaam1, z1, tWaam\WObj:=wWaam;
    ArcL p14, [6.0000,500,5000,1000], seamWaam, weldWaam1, z1, tWaam\WObj:=wWaam;
    ArcL p15, [6.0000,500,5000,1000], seamWaam, weldWaam1, z1, tWaam\WObj:=wWaam;
    ArcL p16, [6.0000,500,5000,1000], seamWaam, weldWaam1, z1, tWaam\WObj:=wWaam;
    ArcL p17, [6.0000,500,5000,1000], seamWaam, weldWaam1, z1, tWaam\WObj:=wWaam;
    ArcL p18, [6.0000,500,5000,1000], seamWaam, weldWaam1, z1, tWaam\WObj:=wWaam;
    ArcLEnd p19, [6.0000,500,5000,1000], seamWaam, weldWaam1, fine, tWaam\WObj:=wWaam;
    MoveL p20, [20.0000,500,5000,1000], fine, tWaam\WObj:=wWaam;
  ENDPROC
ENDMODULE
