MODULE MOD_HEMI
  ! waam-slicer: ABB IRB 2600 torch carried (example layout), 20 points, 2 beads
  ! entry routine HEMI (call it from the task's main); every other name is LOCAL to this module
  ! tWaam.tload: a 3 kg torch, centre of gravity half way to the TCP: identify the real one (LoadIdentify) and set [program.abb] tool_load
  LOCAL PERS tooldata tWaam := [TRUE,[[-86.0000,0.0000,406.0000],[0.9510565,0.0000000,-0.3090170,0.0000000]],[3.0000,[-43.0000,0.0000,203.0000],[1,0,0,0],0.000000,0.000000,0.000000]];
  LOCAL PERS wobjdata wWaam := [FALSE,TRUE,"",[[0.0000,0.0000,0.0000],[1.0000000,0.0000000,0.0000000,0.0000000]],[[0,0,0],[1,0,0,0]]];
  ! ArcWare data (RobotWare 6 Arc): process schedule 1 (arcdata.sched); one welddata per planned travel speed (weld_speed, mm/s) and wire feed (main_arc.wirefeed, m/min)
  ! gas (s): purge_time 0.500, preflow_time 0.300, postflow_time 1.500 ([program.abb] purge_time_s, preflow_time_s, postflow_time_s)
  LOCAL PERS seamdata seamWaam := [0.500,0.300,[1,0,0,0,0,0,0,0,0],0,0,0,0,0,[0,0,0,0,0,0,0,0,0],0,0,[0,0,0,0,0,0,0,0,0],0,0,[0,0,0,0,0,0,0,0,0],1.500];
  LOCAL PERS welddata weldWaam1 := [6.0000,0,[1,0,0,0.6000,0,0,0,0,0],[0,0,0,0,0,0,0,0,0]];
  LOCAL CONST robtarget p1 := [[1145.0000,0.0000,320.0000],[0.0000000,0.0000000,1.0000000,0.0000000],[0,0,0,0],[0.00000,0.00000,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST jointtarget j1 := [[0.00000,35.53246,3.35910,0.00000,87.10844,0.00000],[0.00000,0.00000,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p2 := [[1145.0000,0.0000,300.0000],[0.0000000,0.0000000,-1.0000000,0.0000000],[0,0,0,0],[0.00000,0.00000,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p3 := [[1131.8198,31.8198,300.0000],[0.0000000,0.0000000,1.0000000,0.0000000],[0,0,0,0],[0.00000,0.00000,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p4 := [[1100.0000,45.0000,300.0000],[0.0000000,0.0000000,-1.0000000,0.0000000],[0,0,0,0],[0.00000,0.00000,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p5 := [[1068.1802,31.8198,300.0000],[0.0000000,0.0000000,1.0000000,0.0000000],[0,0,0,0],[0.00000,0.00000,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p6 := [[1055.0000,0.0000,300.0000],[0.0000000,0.0000000,1.0000000,0.0000000],[0,0,0,0],[0.00000,0.00000,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p7 := [[1068.1802,-31.8198,300.0000],[0.0000000,0.0000000,1.0000000,0.0000000],[-1,-1,-1,0],[0.00000,0.00000,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p8 := [[1100.0000,-45.0000,300.0000],[0.0000000,0.0000000,-1.0000000,0.0000000],[-1,-1,-1,0],[0.00000,0.00000,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p9 := [[1131.8198,-31.8198,300.0000],[0.0000000,0.0000000,1.0000000,0.0000000],[-1,-1,-1,0],[0.00000,0.00000,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p10 := [[1131.8198,-31.8198,320.0000],[0.0000000,0.0000000,-1.0000000,0.0000000],[-1,-1,-1,0],[0.00000,0.00000,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p11 := [[1161.6324,0.0000,319.0750],[0.0000000,0.0000000,1.0000000,0.0000000],[0,0,0,0],[6.36620,0.00000,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST jointtarget j11 := [[0.00000,36.48071,1.76362,0.00000,87.75567,0.00000],[6.36620,0.00000,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p12 := [[1161.6324,0.0000,299.0750],[0.0000000,0.0000000,1.0000000,0.0000000],[0,0,0,0],[6.36620,0.00000,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p13 := [[1161.6324,0.0000,299.0750],[0.0000000,0.0000000,1.0000000,0.0000000],[0,0,0,0],[6.36620,-45.00000,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p14 := [[1161.6324,0.0000,299.0750],[0.0000000,0.0000000,1.0000000,0.0000000],[0,0,0,0],[6.36620,-90.00000,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p15 := [[1161.6324,0.0000,299.0750],[0.0000000,0.0000000,1.0000000,0.0000000],[0,0,0,0],[6.36620,-135.00000,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p16 := [[1161.6324,0.0000,299.0750],[0.0000000,0.0000000,1.0000000,0.0000000],[0,0,0,0],[6.36620,-180.00000,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p17 := [[1161.6324,0.0000,299.0750],[0.0000000,0.0000000,1.0000000,0.0000000],[0,0,0,0],[6.36620,-225.00000,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p18 := [[1161.6324,0.0000,299.0750],[0.0000000,0.0000000,1.0000000,0.0000000],[0,0,0,0],[6.36620,-270.00000,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p19 := [[1161.6324,0.0000,299.0750],[0.0000000,0.0000000,1.0000000,0.0000000],[0,0,0,0],[6.36620,-315.00000,9E+09,9E+09,9E+09,9E+09]];
  LOCAL CONST robtarget p20 := [[1161.6324,0.0000,319.0750],[0.0000000,0.0000000,1.0000000,0.0000000],[0,0,0,0],[6.36620,-315.00000,9E+09,9E+09,9E+09,9E+09]];
  PROC HEMI()
    ! positioner: mechanical unit STN1 active for the program
    ActUnit STN1;
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
    ArcL p13, [6.0000,500,5000,7.6857]\T:=5.855, seamWaam, weldWaam1, z1, tWaam\WObj:=wWaam;
    ArcL p14, [6.0000,500,5000,7.6857]\T:=5.855, seamWaam, weldWaam1, z1, tWaam\WObj:=wWaam;
    ArcL p15, [6.0000,500,5000,7.6857]\T:=5.855, seamWaam, weldWaam1, z1, tWaam\WObj:=wWaam;
    ArcL p16, [6.0000,500,5000,7.6857]\T:=5.855, seamWaam, weldWaam1, z1, tWaam\WObj:=wWaam;
    ArcL p17, [6.0000,500,5000,7.6857]\T:=5.855, seamWaam, weldWaam1, z1, tWaam\WObj:=wWaam;
    ArcL p18, [6.0000,500,5000,7.6857]\T:=5.855, seamWaam, weldWaam1, z1, tWaam\WObj:=wWaam;
    ArcLEnd p19, [6.0000,500,5000,7.6857]\T:=5.855, seamWaam, weldWaam1, fine, tWaam\WObj:=wWaam;
    MoveL p20, [20.0000,500,5000,1000], fine, tWaam\WObj:=wWaam;
    DeactUnit STN1;
  ENDPROC
ENDMODULE
